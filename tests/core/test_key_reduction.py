"""Editable keys: few Bezier keys that play the per-frame rotation within the tolerance."""
import numpy as np
import pytest

from rlanimate_addon.core import key_reduction
from rlanimate_addon.core.easing import minimum_jerk
from rlanimate_addon.core.rotations import matrix_to_euler, quat_to_matrix, rotvec_to_quat

FRAMES = 120


def _gesture_like(seed):
    """(N, 3) rotation vectors: a raise, a few swings and a return, as a wave's forearm."""
    t = np.linspace(0.0, 1.0, FRAMES)
    raise_ = minimum_jerk(np.clip(t / 0.3, 0, 1)) * minimum_jerk(np.clip((1 - t) / 0.3, 0, 1))
    rng = np.random.default_rng(seed)
    swing = np.sin(2 * np.pi * 3 * t)[:, None] * rng.uniform(0.2, 0.5, size=3)
    return raise_[:, None] * (rng.uniform(-1.2, 1.2, size=3) + swing)


@pytest.mark.parametrize("mode", ["QUATERNION", "XYZ", "ZXY"])
@pytest.mark.parametrize("tolerance", [0.1, 0.5, 2.0])
def test_reduced_keys_play_within_the_tolerance_with_far_fewer_keys(mode, tolerance):
    quats = rotvec_to_quat(_gesture_like(3))
    values = quats if mode == "QUATERNION" else matrix_to_euler(quat_to_matrix(quats), mode)
    keys, worst = key_reduction.reduce_keys(mode, values, tolerance)
    played = key_reduction.hermite(values, key_reduction.slopes(values), keys)
    error = key_reduction.angles_between(quat_to_matrix(quats), key_reduction.rotation_matrices(mode, played))
    assert worst == pytest.approx(error.max()) and worst <= tolerance
    assert keys[0] == 0 and keys[-1] == FRAMES - 1
    assert len(keys) < FRAMES / 4, f"{len(keys)} keys for {FRAMES} frames"
    assert np.allclose(played[keys], values[keys]), "the curve passes through its keys"


def test_a_tighter_tolerance_keeps_more_keys():
    values = rotvec_to_quat(_gesture_like(8))
    counts = [len(key_reduction.reduce_keys("QUATERNION", values, t)[0]) for t in (2.0, 0.5, 0.1)]
    assert counts[0] < counts[1] < counts[2]


def test_hermite_with_every_frame_a_key_is_the_data():
    values = np.random.default_rng(1).normal(size=(20, 4))
    assert np.allclose(key_reduction.hermite(values, key_reduction.slopes(values), list(range(20))), values)
