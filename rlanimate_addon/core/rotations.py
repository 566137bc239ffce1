"""Rotation conversions in plain numpy (Blender's Python has no scipy).

Quaternions are (w, x, y, z), Blender's order. Rotation vectors (exponential map) are axis * angle,
with angle in [0, pi]. Every function takes arrays with any leading batch shape.
"""
import numpy as np
from numpy.typing import ArrayLike

_SMALL = 1e-8


def quat_to_rotvec(quat: ArrayLike) -> np.ndarray:
    """(..., 4) unit quaternions -> (..., 3) rotation vectors, on the short arc (angle <= pi)."""
    q = np.asarray(quat, dtype=np.float64)
    q = np.where(q[..., :1] < 0.0, -q, q)  # same rotation, w >= 0 gives angle <= pi
    w = np.clip(q[..., 0], -1.0, 1.0)
    xyz = q[..., 1:]
    sin_half = np.linalg.norm(xyz, axis=-1)
    angle = 2.0 * np.arctan2(sin_half, w)
    # angle / sin(angle/2), with its limit 2 (+ angle^2 / 12) near zero
    scale = np.where(sin_half > _SMALL, angle / np.maximum(sin_half, _SMALL), 2.0 + angle**2 / 12.0)
    return xyz * scale[..., None]


def rotvec_to_quat(rotvec: ArrayLike) -> np.ndarray:
    """(..., 3) rotation vectors -> (..., 4) unit quaternions with w >= 0."""
    r = np.asarray(rotvec, dtype=np.float64)
    angle = np.linalg.norm(r, axis=-1)
    half = 0.5 * angle
    # sin(angle/2) / angle, with its limit 1/2 (- angle^2 / 48) near zero
    scale = np.where(angle > _SMALL, np.sin(half) / np.maximum(angle, _SMALL), 0.5 - angle**2 / 48.0)
    return np.concatenate([np.cos(half)[..., None], r * scale[..., None]], axis=-1)


def quat_to_matrix(quat: ArrayLike) -> np.ndarray:
    """(..., 4) quaternions -> (..., 3, 3) rotation matrices (columns are the rotated axes)."""
    q = np.asarray(quat, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    m = np.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ], axis=-1)
    return m.reshape(q.shape[:-1] + (3, 3))


def matrix_to_quat(matrix: ArrayLike) -> np.ndarray:
    """(..., 3, 3) rotation matrices -> (..., 4) unit quaternions with w >= 0 (Shepperd's method)."""
    m = np.asarray(matrix, dtype=np.float64)
    batch = m.shape[:-2]
    m = m.reshape(-1, 3, 3)
    trace = np.trace(m, axis1=1, axis2=2)
    # Pick the numerically largest of w, x, y, z per matrix and derive the rest from it.
    candidates = np.stack([trace, m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]], axis=1)
    choice = np.argmax(candidates, axis=1)
    q = np.empty((m.shape[0], 4))
    for k in range(4):
        sel = choice == k
        if not np.any(sel):
            continue
        s = m[sel]
        if k == 0:
            r = np.sqrt(1.0 + trace[sel]) * 2.0
            q[sel] = np.stack([0.25 * r, (s[:, 2, 1] - s[:, 1, 2]) / r,
                               (s[:, 0, 2] - s[:, 2, 0]) / r, (s[:, 1, 0] - s[:, 0, 1]) / r], axis=1)
        elif k == 1:
            r = np.sqrt(1.0 + s[:, 0, 0] - s[:, 1, 1] - s[:, 2, 2]) * 2.0
            q[sel] = np.stack([(s[:, 2, 1] - s[:, 1, 2]) / r, 0.25 * r,
                               (s[:, 0, 1] + s[:, 1, 0]) / r, (s[:, 0, 2] + s[:, 2, 0]) / r], axis=1)
        elif k == 2:
            r = np.sqrt(1.0 + s[:, 1, 1] - s[:, 0, 0] - s[:, 2, 2]) * 2.0
            q[sel] = np.stack([(s[:, 0, 2] - s[:, 2, 0]) / r, (s[:, 0, 1] + s[:, 1, 0]) / r,
                               0.25 * r, (s[:, 1, 2] + s[:, 2, 1]) / r], axis=1)
        else:
            r = np.sqrt(1.0 + s[:, 2, 2] - s[:, 0, 0] - s[:, 1, 1]) * 2.0
            q[sel] = np.stack([(s[:, 1, 0] - s[:, 0, 1]) / r, (s[:, 0, 2] + s[:, 2, 0]) / r,
                               (s[:, 1, 2] + s[:, 2, 1]) / r, 0.25 * r], axis=1)
    q = np.where(q[:, :1] < 0.0, -q, q)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q.reshape(batch + (4,))


def rotvec_to_matrix(rotvec: ArrayLike) -> np.ndarray:
    """(..., 3) rotation vectors -> (..., 3, 3) rotation matrices."""
    return quat_to_matrix(rotvec_to_quat(rotvec))


def matrix_to_rotvec(matrix: ArrayLike) -> np.ndarray:
    """(..., 3, 3) rotation matrices -> (..., 3) rotation vectors."""
    return quat_to_rotvec(matrix_to_quat(matrix))


_AXES = {"X": 0, "Y": 1, "Z": 2}


def _axis_matrix(axis, angle):
    """(..., 3, 3) rotations by angle (...) about coordinate axis 0, 1 or 2."""
    rotvec = np.zeros(np.shape(angle) + (3,))
    rotvec[..., axis] = angle
    return rotvec_to_matrix(rotvec)


def euler_to_matrix(euler: ArrayLike, order: str = "XYZ") -> np.ndarray:
    """(..., 3) Euler angles in Blender's convention -> (..., 3, 3): order 'XYZ' applies X first (Rz Ry Rx)."""
    e = np.asarray(euler, dtype=np.float64)
    m = np.broadcast_to(np.eye(3), e.shape[:-1] + (3, 3))
    for axis in order:
        m = _axis_matrix(_AXES[axis], e[..., _AXES[axis]]) @ m
    return m


def matrix_to_euler(matrix: ArrayLike, order: str = "XYZ", previous: ArrayLike | None = None) -> np.ndarray:
    """(N, 3, 3) rotations -> (N, 3) Euler angles (Blender's order convention, channels X, Y, Z).

    Each frame takes, of the two Euler triples of its rotation and their 2 pi turns, the one nearest
    the frame before (the first frame: nearest `previous` (3,), when given), as Blender's
    `Matrix.to_euler(order, euler_compat)` does, so keys interpolate without flips.
    """
    m = np.asarray(matrix, dtype=np.float64)
    i, j, k = (_AXES[a] for a in order)
    sign = 1.0 if (j - i) % 3 == 1 else -1.0  # an even permutation of X, Y, Z
    first = np.arctan2(sign * m[:, k, j], m[:, k, k])
    middle = np.arcsin(np.clip(-sign * m[:, k, i], -1.0, 1.0))
    last = np.arctan2(sign * m[:, j, i], m[:, i, i])
    angles = np.zeros((len(m), 3))
    angles[:, i], angles[:, j], angles[:, k] = first, middle, last
    other = angles.copy()
    other[:, i], other[:, j], other[:, k] = first + np.pi, np.pi - middle, last + np.pi
    out = np.empty_like(angles)
    reference = None if previous is None else np.asarray(previous, dtype=np.float64)
    for t in range(len(m)):
        options = [angles[t], other[t]]
        if reference is not None:
            options = [o + 2.0 * np.pi * np.round((reference - o) / (2.0 * np.pi)) for o in options]
            out[t] = min(options, key=lambda o: np.abs(o - reference).sum())
        else:
            out[t] = options[0]
        reference = out[t]
    return out


def quat_to_axis_angle(quat: ArrayLike) -> np.ndarray:
    """(..., 4) quaternions -> (..., 4) Blender axis-angle (angle, x, y, z); continuous quaternions give
    continuous values (the angle runs up to 2 pi rather than flipping the axis)."""
    q = np.asarray(quat, dtype=np.float64)
    sin_half = np.linalg.norm(q[..., 1:], axis=-1)
    angle = 2.0 * np.arctan2(sin_half, q[..., 0])
    axis = np.where(sin_half[..., None] > _SMALL, q[..., 1:] / np.maximum(sin_half, _SMALL)[..., None], [0.0, 1.0, 0.0])
    return np.concatenate([angle[..., None], axis], axis=-1)
