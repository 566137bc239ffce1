"""FK of action rotations and the numpy FK environment: the spec's rest description, decoding, input checks."""
import numpy as np
import pytest

from rlanimate_addon.core import kinematics, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion import fk
from trainer.motion.fk import NumpyFKEnvironment

JOINTS = len(skeleton.ACTION_JOINTS)


@pytest.fixture
def env():
    return NumpyFKEnvironment()


def _head(name):
    return np.asarray(skeleton.BONE_BY_NAME[name].head)


def test_bone_heads_follow_the_kinematic_chain():
    rng = np.random.default_rng(1)
    actions = rng.uniform(-1, 1, (4, JOINTS, 3))
    heads = fk.bone_heads(actions, {"LeftHandIndex2": rng.uniform(-1, 1, (4, 3))})
    lengths = [np.linalg.norm(heads[:, kinematics.bone_index(b.name)] - heads[:, kinematics.bone_index(b.parent)],
                              axis=-1) for b in skeleton.BONES if b.parent]
    rest = [np.linalg.norm(_head(b.name) - _head(b.parent)) for b in skeleton.BONES if b.parent]
    np.testing.assert_allclose(np.stack(lengths, axis=1), np.broadcast_to(rest, (4, len(rest))), atol=1e-9)
    assert np.abs(heads - fk.bone_heads(np.zeros_like(actions))).max() > 0.3  # the bones did move
    tip = kinematics.bone_index("LeftHandIndex3")
    assert np.linalg.norm(heads[:, tip] - fk.bone_heads(actions)[:, tip], axis=-1).min() > 1e-4  # the extra bone


def test_rest_description_matches_the_spec_coordinates(env):
    result = env.evaluate(np.zeros((1, JOINTS, 3)))
    description = result.descriptions[0]
    assert description.shape == (spaces.DESCRIPTION_SIZE,)
    effectors = description[spaces.DESCRIPTION_EFFECTORS].reshape(4, 3)
    assert np.allclose(effectors[0], (0, -1, 0), atol=1e-6) and np.allclose(effectors[1], (0, -1, 0), atol=1e-6)
    for row, side in ((2, "Left"), (3, "Right")):
        finger = _head(f"{side}HandIndex4") - _head(f"{side}HandIndex1")
        assert np.allclose(effectors[row], finger / np.linalg.norm(finger), atol=1e-6)
    positions = result.joint_positions[0]
    for row, (_, bone) in enumerate(skeleton.DESCRIPTION_JOINTS):
        assert np.allclose(positions[row], _head(bone), atol=1e-6)
    assert np.allclose(positions[6], (0.70, 0.0, 1.45), atol=1e-6)  # left wrist: the head of LeftHand


def test_describe_actions_decodes_with_the_bounds(env):
    rng = np.random.default_rng(5)
    actions = rng.uniform(0, 1, (3, spaces.ACTION_SIZE))
    direct = env.evaluate(spaces.decode_action(actions))
    decoded = env.describe_actions(actions)
    assert np.allclose(decoded.descriptions, direct.descriptions)
    centred = env.describe_actions(np.full((1, spaces.ACTION_SIZE), 0.5))  # symmetric bounds: 0.5 is rest
    rest = env.evaluate(np.zeros((1, JOINTS, 3)))
    assert np.allclose(centred.joint_positions[0], rest.joint_positions[0], atol=1e-6)


@pytest.mark.parametrize("bad, extra, message", [
    (np.zeros((2, 14, 3)), None, "shape"),
    (np.zeros((2, 45)), None, "shape"),
    (np.full((2, JOINTS, 3), np.nan), None, "NaN"),
    (np.zeros((2, JOINTS, 3)), {"LeftHandIndex2": np.zeros((3, 3))}, "shape"),
    (np.zeros((2, JOINTS, 3)), {"LeftHandIndex2": np.full((2, 3), np.inf)}, "NaN"),
    (np.zeros((2, JOINTS, 3)), {"LeftTail": np.zeros((2, 3))}, "no bone"),
])
def test_bad_input_raises_a_clear_error(env, bad, extra, message):
    with pytest.raises(RLAnimateError, match=message):
        env.evaluate(bad, extra)
