import numpy as np
import pytest

from rlanimate_addon.core import rotations


def _random_rotvecs(n, seed=0):
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    return axes * rng.uniform(0.0, np.pi - 1e-3, size=(n, 1))


def test_rotvec_quat_round_trip():
    r = _random_rotvecs(500)
    np.testing.assert_allclose(rotations.quat_to_rotvec(rotations.rotvec_to_quat(r)), r, atol=1e-9)


def test_matrix_round_trip_and_orthonormal():
    r = _random_rotvecs(500, seed=1)
    m = rotations.rotvec_to_matrix(r)
    np.testing.assert_allclose(m @ np.swapaxes(m, -1, -2), np.broadcast_to(np.eye(3), m.shape), atol=1e-12)
    np.testing.assert_allclose(rotations.matrix_to_rotvec(m), r, atol=1e-8)


def test_quarter_turn_about_z_maps_x_to_y():
    m = rotations.rotvec_to_matrix(np.array([0.0, 0.0, np.pi / 2]))
    np.testing.assert_allclose(m @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-12)


def test_small_angles_are_stable():
    r = np.array([[1e-12, 0.0, 0.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(rotations.quat_to_rotvec(rotations.rotvec_to_quat(r)), r, atol=1e-15)


def test_negative_w_gives_the_short_arc():
    q = -rotations.rotvec_to_quat(np.array([0.3, 0.0, 0.0]))
    np.testing.assert_allclose(rotations.quat_to_rotvec(q), [0.3, 0.0, 0.0], atol=1e-12)


def test_quat_mean_of_close_rotations_whatever_their_signs_and_of_opposite_swings():
    rng = np.random.default_rng(3)
    centre = rotations.rotvec_to_quat(np.array([0.3, -0.2, 0.5]))
    spread = rotations.quat_multiply(centre, rotations.rotvec_to_quat(rng.normal(scale=0.05, size=(50, 3))))
    signed = spread * rng.choice([-1.0, 1.0], size=(50, 1))
    mean = rotations.quat_mean(signed)
    assert np.linalg.norm(mean) == pytest.approx(1.0)
    assert abs(np.sum(mean * centre)) > np.cos(np.radians(2.0) / 2), "within 2 degrees of the centre"
    swings = rotations.rotvec_to_quat(np.array([[[0.0, 0.0, 0.8]], [[0.0, 0.0, -0.8]]]))  # (2, 1, 4)
    assert np.allclose(rotations.quat_mean(swings), [[1.0, 0.0, 0.0, 0.0]]), "opposite swings average to still"
