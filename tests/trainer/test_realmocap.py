"""Real motion capture: names, splits, relaxed hand, labels on import, and the experiment pipeline end to end."""
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from rlanimate_addon.core import kinematics, skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer import realmocap

HAVE_DATA = (realmocap.REALMOCAP_DIR / "wave").is_dir()
needs_data = pytest.mark.skipif(not HAVE_DATA, reason=f"real motion capture not found at {realmocap.REALMOCAP_DIR} "
                                                      "(../shared/realmocap/ beside the repository)")
WAVE_NAMES = [f"dataset-2_wave-{side}-hand_{style}_{take:03d}.bvh" for side in ("left", "right")
              for style in realmocap.STYLES for take in range(1, 11)]


def test_parse_name_reads_content_arm_style_and_take():
    assert realmocap.parse_name("x/dataset-2_wave-left-hand_feminine_009.bvh") == {
        "content": "wave", "arm": "LEFT", "style": "feminine", "take": "009"}
    assert realmocap.parse_name("dataset-1_guide_not-confident_001.bvh") == {
        "content": "guide", "arm": None, "style": "not-confident", "take": "001"}
    with pytest.raises(RLAnimateError, match="Bandai Namco"):
        realmocap.parse_name("wave_001.bvh")


def test_splits_match_the_experiments():
    clips = [SimpleNamespace(**realmocap.parse_name(name)) for name in WAVE_NAMES]
    train, test = realmocap.wave_split(clips)
    assert (len(train), len(test)) == (112, 28)
    assert {c.take for c in test} == {"009", "010"}
    train, test = realmocap.style_holdout_split(clips)
    assert (len(train), len(test)) == (100, 40)
    assert not {c.style for c in train} & {c.style for c in test}


def test_relaxed_hand_curls_the_fingers_towards_the_palm():
    clip = SimpleNamespace(rotvecs=np.zeros((3, len(skeleton.ACTION_JOINTS), 3)), fingers={})
    from trainer.clip_import import MotionClip
    relaxed = realmocap.relaxed_hand(MotionClip("c", "", 30.0, clip.rotvecs))
    for side in ("Left", "Right"):
        index1 = relaxed.rotvecs[:, skeleton.ACTION_JOINTS.index(side + "HandIndex1")]
        pose = kinematics.pose_matrices({side + "HandIndex1": index1[0], **{k: v[0] for k, v in relaxed.fingers.items()}})
        heads = kinematics.head_positions(pose)
        for finger in ("Index", "Pinky"):
            base = heads[kinematics.bone_index(f"{side}Hand{finger}1")]
            tip = heads[kinematics.bone_index(f"{side}Hand{finger}4")]
            assert tip[2] < base[2] - 0.005  # T-pose, palm down: a curl lowers the tip
        assert np.all(np.isfinite(relaxed.rotvecs))


def test_missing_folder_gets_a_clear_error(tmp_path):
    with pytest.raises(RLAnimateError, match="not at"):
        realmocap.require_realmocap(tmp_path)


@needs_data
def test_imported_clips_are_labelled_from_their_motion(tmp_path):
    wave = realmocap.import_real_clip(realmocap.REALMOCAP_DIR / "wave" / "dataset-2_wave-right-hand_normal_003.bvh",
                                      tmp_path)
    assert (wave.behaviour, wave.arm, wave.named_arm, wave.style, wave.take) == ("WAVE", "RIGHT", "RIGHT", "normal", "003")
    assert 0.0 <= wave.exaggeration <= 1.0 and wave.attributes == wave.exaggeration
    assert np.allclose(wave.rotvecs[:, skeleton.ACTION_JOINTS.index("RightHandIndex1")],
                       (realmocap.RELAXED_HAND["Index"], 0.0, 0.0))
    guide = realmocap.import_real_clip(realmocap.REALMOCAP_DIR / "guide" / "dataset-1_guide_normal_001.bvh", tmp_path)
    assert guide.behaviour == "POINT" and guide.arm == "RIGHT"
    assert abs(np.linalg.norm(guide.attributes) - 1.0) < 1e-9
    assert 0 < guide.label.hold_frame < guide.frames - 1


@needs_data
def test_experiment_pipeline_runs_end_to_end_on_a_few_clips(tmp_path):
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    from trainer import baselines
    from trainer.algorithm import ClipReferences
    from trainer.fk_env import FKEnvironment
    folder = realmocap.REALMOCAP_DIR / "wave"
    clips = [realmocap.import_real_clip(folder / name, tmp_path / "cache") for name in
             ("dataset-2_wave-left-hand_feminine_001.bvh", "dataset-2_wave-left-hand_active_002.bvh",
              "dataset-2_wave-left-hand_normal_009.bvh")]
    train, test = realmocap.wave_split(clips)
    env = FKEnvironment(instances=4)
    references = ClipReferences(env)
    session = realmocap.RealSession(env, references, train, test)
    report, agent = realmocap.train_agent(session, "tiny", "wave", 1, "debug", 0, runs=tmp_path)
    assert agent.path.is_file() and report["episodes"] == 1
    exported = baselines.AgentMethod(agent.path).generate("WAVE", "LEFT", 0.4, 40)
    np.testing.assert_allclose(exported, agent.generate("WAVE", "LEFT", 0.4, 40), atol=1e-4)
    methods = {"rlanimate": agent, "nearest_clip": baselines.NearestClip(train),
               "procedural_ik": baselines.ProceduralIK(baselines.neutral_pose(train))}
    comparison = realmocap.compare(methods, test, env, references)
    for result in comparison.values():
        assert np.isfinite(result["score"]) and 0.0 <= result["smoothness"] <= 100.0
        assert 0.0 <= result["label_error"] <= 1.0
    # The nearest clip to the normal wave (e ~ 0.7) is the active one, not the feminine one.
    assert methods["nearest_clip"].nearest("WAVE", "LEFT", test[0].exaggeration).style == "active"
    angles = realmocap.guide_angles(methods["procedural_ik"], [_as_point(test[0])], env)
    assert 0.0 <= angles["mean_forearm_angle_deg"] <= 180.0
    picture = tmp_path / "frames.png"
    generated = methods["rlanimate"].generate("WAVE", "LEFT", test[0].exaggeration, test[0].frames)
    realmocap.frames_figure(env, [("t", test[0].rotvecs, generated)], picture, times=(0.5,))
    assert picture.stat().st_size > 1000


def _as_point(clip):
    import copy
    from trainer import autolabel
    label = autolabel.label_point(clip.rotvecs, clip.arm)
    point = copy.copy(clip)
    point.behaviour, point.attributes, point.label = "POINT", label.direction, label
    return point
