"""Procedural IK: the pointing finger aims at the target, waves grow with exaggeration."""
import numpy as np
import pytest

from rlanimate_addon.core import skeleton, spaces
from trainer.blender_io.fk_env import FKEnvironment
from trainer.blender_io.procedural_ik import POINT_TARGET_DISTANCE, ProceduralIK
from trainer.blender_io.rig_session import new_empty_scene

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


@pytest.mark.parametrize("arm", ["LEFT", "RIGHT"])
def test_procedural_point_aims_the_finger_at_the_target(scene, arm):
    env, ik = scene
    rng = np.random.default_rng()
    target = np.array([rng.uniform(-1.0, 1.0), rng.uniform(-3.0, -1.5), rng.uniform(0.5, 2.5)])
    direction = spaces.pointing_direction(arm, target)
    motion = ik.generate("POINT", arm, direction, 90)
    _valid(motion, 90)
    np.testing.assert_allclose(motion[[0, -1]], np.broadcast_to(ik.neutral, (2, JOINTS, 3)), atol=1e-6)
    heads = env.evaluate(motion).bone_heads
    side = skeleton.ARM_PREFIX[arm]
    base = heads[45, env.bone_names.index(side + "HandIndex1")]
    tip = heads[45, env.bone_names.index(side + "HandIndex4")]
    aim = skeleton.shoulder_rest_position(arm) + POINT_TARGET_DISTANCE * direction
    cos = (tip - base) @ (aim - base) / np.linalg.norm(tip - base) / np.linalg.norm(aim - base)
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))) < 3.0


def test_procedural_wave_grows_with_exaggeration(scene):
    env, ik = scene
    from trainer.motion import autolabel
    labels = [autolabel.label_wave(ik.generate("WAVE", "LEFT", e, 120)) for e in (0.0, 0.5, 1.0)]
    assert all(label.arm == "LEFT" for label in labels)
    assert labels[0].elevation < labels[1].elevation < labels[2].elevation
    assert labels[0].stroke < labels[1].stroke < labels[2].stroke
