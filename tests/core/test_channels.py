"""Rotation keys in each rotation mode, for NLA Replace and Combine layers."""
import numpy as np
import pytest

from rlanimate_addon.core import channels, rotations
from rlanimate_addon.core.rotations import (
    euler_to_matrix,
    matrix_to_euler,
    quat_to_matrix,
    rotvec_to_matrix,
    rotvec_to_quat,
)

RNG = np.random.default_rng(5)


def _path(count=60, scale=0.25, start=(0.0, 0.0, 0.0)):
    return rotvec_to_quat(np.asarray(start) + np.cumsum(RNG.normal(scale=scale, size=(count, 3)), axis=0))


def _channel_values(mode, quats):
    if mode == "QUATERNION":
        return quats
    if mode == "AXIS_ANGLE":
        return channels.quat_to_axis_angle(quats)
    return matrix_to_euler(quat_to_matrix(quats), mode)


def _rotation(mode, values):
    if mode == "QUATERNION":
        return quat_to_matrix(values)
    if mode == "AXIS_ANGLE":
        return rotvec_to_matrix(values[:, 1:] * values[:, :1])
    return euler_to_matrix(values, mode)


@pytest.mark.parametrize("mode", channels.MODES)
@pytest.mark.parametrize("blend_type", channels.BLEND_TYPES)
def test_keys_play_the_keyed_rotation_in_each_mode_and_layer_without_jumps(mode, blend_type):
    keyed, below = _path(), _path(scale=0.05, start=(0.3, 2.9, 0.0))
    below_values = _channel_values(mode, below)
    keys = channels.rotation_keys(mode, keyed, below, below_values, blend_type)
    assert keys.shape == (60, 3 if len(mode) == 3 and mode != "AXIS_ANGLE" else 4)
    if blend_type == "REPLACE":
        played = keys
    elif mode == "QUATERNION":  # Blender's Combine: result = below @ key
        played = rotations.quat_multiply(below_values, keys)
    else:  # Combine adds Euler and axis-angle channels
        played = below_values + keys
    assert np.allclose(_rotation(mode, played), quat_to_matrix(keyed), atol=1e-9)
    assert np.abs(np.diff(keys, axis=0)).max() < 2.5, "keys must not flip by pi or 2 pi between frames"


def test_euler_keys_continue_the_turn_count_of_the_animation_underneath():
    below_values = np.tile([0.1, 0.2, 2 * np.pi + 0.3], (10, 1))  # an animation one turn round Z
    below = rotvec_to_quat(np.zeros((10, 3)))
    keyed = np.array([channels.matrix_to_quat(euler_to_matrix(below_values[0], "XYZ"))] * 10)
    keys = channels.rotation_keys("XYZ", keyed, below, below_values, "REPLACE")
    assert np.allclose(keys, below_values, atol=1e-9)
