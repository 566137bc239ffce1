"""The bpy FK environment: it agrees with the numpy one, and drives any saved state of the rig from rest."""
import numpy as np
import pytest

from rlanimate_addon.core import kinematics, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io import rig_session
from trainer.motion.fk import NumpyFKEnvironment
from trainer.paths import SAMPLE_RIG_FBX

bpy = pytest.importorskip("bpy")
from trainer.blender_io.fk_env import FKEnvironment  # noqa: E402

JOINTS = len(skeleton.ACTION_JOINTS)


@pytest.fixture
def env():
    rig_session.new_empty_scene()
    return FKEnvironment(instances=4)


def _numpy_heads(action_rotvecs, extra=None):
    """(P, n_bones, 3) bone heads from core.kinematics, in skeleton.BONE_NAMES order."""
    local = {joint: action_rotvecs[:, i] for i, joint in enumerate(skeleton.ACTION_JOINTS)}
    local.update(extra or {})
    return kinematics.head_positions(kinematics.pose_matrices(local))


def _head(name):
    return np.asarray(skeleton.BONE_BY_NAME[name].head)


def test_agrees_with_the_numpy_environment_on_random_poses(env):
    """Positions to 1e-6 m. The four effector directions are unit vectors, two of them along a 3 cm finger,
    so Blender's float32 pose matrices move them by up to ~2e-6: they are held to 1e-5."""
    rng = np.random.default_rng(7)
    count = 11  # three batches of 4 instances, the last one partial
    actions = spaces.decode_action(rng.uniform(0, 1, size=(count, spaces.ACTION_SIZE)))
    fingers = {"LeftHandIndex2": rng.uniform(-1, 1, (count, 3)), "RightHandThumb1": rng.uniform(-1, 1, (count, 3))}
    result, expected = env.evaluate(actions, fingers), NumpyFKEnvironment().evaluate(actions, fingers)
    assert env.bone_names == NumpyFKEnvironment.bone_names == skeleton.BONE_NAMES
    assert result.bone_heads.shape == expected.bone_heads.shape == (count, len(skeleton.BONES), 3)
    moved = np.linalg.norm(expected.bone_heads - _numpy_heads(np.zeros_like(actions)), axis=-1)
    assert moved.max() > 0.3, "the poses must be far from rest for the comparison to mean anything"
    assert np.abs(result.bone_heads - expected.bone_heads).max() < 1e-6
    assert np.abs(result.joint_positions - expected.joint_positions).max() < 1e-6
    assert np.abs(result.descriptions - expected.descriptions).max() < 1e-5


def test_bones_left_out_return_to_rest(env):
    rng = np.random.default_rng(3)
    count = env.instances
    env.evaluate(rng.uniform(-1, 1, (count, JOINTS, 3)), {"LeftHandIndex2": rng.uniform(-1, 1, (count, 3))})
    result = env.evaluate(np.zeros((count, JOINTS, 3)))
    assert np.abs(result.bone_heads - _numpy_heads(np.zeros((count, JOINTS, 3)))).max() < 1e-6


def _modified_rig(tmp_path, change):
    """Path of a copy of the sample rig saved after `change(rig)`."""
    rig_session.new_empty_scene()
    rig = rig_session.load_rig()
    change(rig)
    path = tmp_path / "modified.blend"
    bpy.data.libraries.write(str(path), {rig})
    rig_session.new_empty_scene()
    return path


def test_positions_are_in_metres_whatever_the_object_scale(tmp_path):
    def halve(rig):
        rig.scale = (0.5, 0.5, 0.5)

    result = FKEnvironment(_modified_rig(tmp_path, halve), instances=1).evaluate(np.zeros((1, JOINTS, 3)))
    assert np.allclose(result.joint_positions[0, 6], 0.5 * _head("LeftHand"), atol=1e-6)


def test_euler_bones_and_a_posed_rig_are_driven_from_rest(tmp_path):
    def pose_with_eulers(rig):
        for bone in rig.pose.bones:
            bone.rotation_mode = "XYZ"
            bone.rotation_euler = (0.3, 0.2, 0.1)
        rig.pose.bones[skeleton.PREFIX + "Hips"].location = (0.1, 0.2, 0.3)
        rig.pose.bones[skeleton.PREFIX + "LeftArm"].scale = (2.0, 2.0, 2.0)

    actions = np.random.default_rng(4).uniform(-1, 1, (3, JOINTS, 3))
    result = FKEnvironment(_modified_rig(tmp_path, pose_with_eulers), instances=2).evaluate(actions)
    assert np.abs(result.bone_heads - _numpy_heads(actions)).max() < 1e-5


def test_fbx_rig_gives_the_same_results_as_the_blend():
    rig_session.new_empty_scene()
    actions = np.random.default_rng(2).uniform(-1, 1, (2, JOINTS, 3))
    from_fbx = FKEnvironment(SAMPLE_RIG_FBX, instances=2).evaluate(actions)
    assert np.abs(from_fbx.bone_heads - _numpy_heads(actions)).max() < 1e-4


def test_bad_setup_raises_clear_errors(tmp_path):
    with pytest.raises(RLAnimateError, match="at least 1 instance"):
        FKEnvironment(instances=0)
    with pytest.raises(RLAnimateError, match="does not exist"):
        FKEnvironment(tmp_path / "missing.blend")


def test_numpy_describe_matches_the_environment(env):
    rng = np.random.default_rng(11)
    actions = rng.uniform(-1.0, 1.0, size=(5, JOINTS, 3))
    np.testing.assert_allclose(kinematics.describe(actions), env.evaluate(actions).descriptions, atol=1e-5)
