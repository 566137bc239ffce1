"""Baselines: nearest-clip retrieval and procedural IK produce valid clips that the evaluator scores."""
import numpy as np
import pytest

from rlanimate_addon.core import skeleton, spaces
from trainer.agent.algorithm import ClipReferences
from trainer.blender_io.fk_env import FKEnvironment
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.blender_io.rig_session import new_empty_scene
from trainer.evaluation import baselines
from trainer.motion.clip import MotionClip

JOINTS = len(skeleton.ACTION_JOINTS)


@pytest.fixture(scope="module")
def scene():
    """Factory-fresh scene with the FK environment and the procedural-IK rig side by side."""
    new_empty_scene()
    env = FKEnvironment(instances=8)
    neutral = np.zeros((JOINTS, 3))
    for side, sign in (("Left", 1.0), ("Right", -1.0)):  # arms lowered 70 deg from the T-pose
        rest = skeleton.rest_frame(skeleton.BONE_BY_NAME[side + "Arm"])
        neutral[skeleton.ACTION_JOINTS.index(side + "Arm")] = rest.T @ np.array([0.0, sign * 1.22, 0.0])
    return env, ProceduralIK(neutral)


def _valid(motion, frames):
    assert motion.shape == (frames, JOINTS, 3)
    assert np.all(np.isfinite(motion))


def test_time_warp_keeps_the_ends_and_resamples_the_length():
    rng = np.random.default_rng(0)
    clip = rng.normal(0.0, 0.4, (40, JOINTS, 3))
    warped = baselines.time_warp(clip, 73)
    _valid(warped, 73)
    np.testing.assert_allclose(warped[[0, -1]], clip[[0, -1]], atol=1e-9)
    np.testing.assert_allclose(baselines.time_warp(clip, 40), clip, atol=1e-9)


def test_nearest_clip_retrieves_the_closest_label(scene):
    _, ik = scene
    library = [MotionClip(f"wave_{e}", "", 30.0, ik.generate("WAVE", "RIGHT", e, 60 + int(100 * e)),
                          behaviour="WAVE", arm="RIGHT", attributes=e) for e in (0.1, 0.5, 0.9)]
    up = spaces.pointing_direction("LEFT", [1.0, -2.0, 2.5])
    library.append(MotionClip("point_up", "", 30.0, ik.generate("POINT", "LEFT", up, 70),
                              behaviour="POINT", arm="LEFT", attributes=up))
    nearest = baselines.NearestClip(library)
    assert nearest.nearest("WAVE", "RIGHT", 0.62).name == "wave_0.5"
    motion = nearest.generate("WAVE", "RIGHT", 0.62, 97)
    _valid(motion, 97)
    np.testing.assert_allclose(motion[[0, -1]], library[1].rotvecs[[0, -1]], atol=1e-9)
    assert nearest.nearest("POINT", "LEFT", [0.3, -1.0, 0.4]).name == "point_up"
    from rlanimate_addon.core.errors import RLAnimateError
    with pytest.raises(RLAnimateError, match="right arm"):
        nearest.generate("POINT", "RIGHT", up, 50)


def test_the_evaluator_scores_baseline_clips(scene):
    env, ik = scene
    e = 0.7
    reference = MotionClip("ref", "", 30.0, ik.generate("WAVE", "RIGHT", e, 80), behaviour="WAVE",
                           arm="RIGHT", attributes=e)
    other = MotionClip("other", "", 30.0, ik.generate("WAVE", "RIGHT", 0.2, 60), behaviour="WAVE",
                       arm="RIGHT", attributes=0.2)
    references = ClipReferences(env)
    for baseline in (baselines.NearestClip([other]), ik):
        motions = baselines.generate_for(baseline, [reference])
        _valid(motions[0], 80)
        result = baselines.evaluate_motions(env, motions, [reference], references)
        assert np.isfinite(result["score"]) and 0.0 <= result["smoothness"] <= 100.0
        assert result["clips"][0]["name"] == "ref"
    exact = baselines.evaluate_motions(env, [reference.rotvecs], [reference], references)
    assert exact["score"] == pytest.approx(100.0)
    copied = baselines.evaluate_motions(env, baselines.generate_for(baselines.NearestClip([other]), [reference]),
                                        [reference], references)
    assert copied["score"] < exact["score"] - 0.5  # a different exaggeration costs score
