"""Rotation conversions in plain numpy (Blender's Python has no scipy).

Quaternions are (w, x, y, z), Blender's order. Rotation vectors (exponential map) are axis * angle,
with angle in [0, pi]. Every function takes arrays with any leading batch shape.
"""
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

_SMALL = 1e-8


def _components(values: npt.NDArray[np.float64], size: int) -> npt.NDArray[np.float64]:
    """(size, M) contiguous rows of the last axis's components of (..., size) values, M their count: the
    conversions below work on whole rows, which numpy runs about twice as fast as strided columns."""
    return np.ascontiguousarray(np.reshape(values, (-1, size)).T)


def _length(*components: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Euclidean length of vectors given as component rows, summed in np.linalg.norm's order."""
    total = components[0] * components[0]
    for c in components[1:]:
        total += c * c
    length: npt.NDArray[np.float64] = np.sqrt(total)
    return length


def _joined(rows: Sequence[npt.NDArray[np.float64]], batch: tuple[int, ...]) -> npt.NDArray[np.float64]:
    """(..., K) array of K component rows (M,) with leading shape `batch`."""
    return np.stack(rows, axis=-1).reshape(tuple(batch) + (len(rows),))


def quat_to_rotvec(quat: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 4) unit quaternions -> (..., 3) rotation vectors, on the short arc (angle <= pi)."""
    q = np.asarray(quat, dtype=np.float64)
    w, x, y, z = _components(q, 4)
    flip = w < 0.0  # same rotation, w >= 0 gives angle <= pi
    w, x, y, z = (np.where(flip, -c, c) for c in (w, x, y, z))
    w = np.clip(w, -1.0, 1.0)
    sin_half = _length(x, y, z)
    angle = 2.0 * np.arctan2(sin_half, w)
    # angle / sin(angle/2), with its limit 2 (+ angle^2 / 12) near zero
    scale = np.where(sin_half > _SMALL, angle / np.maximum(sin_half, _SMALL), 2.0 + angle**2 / 12.0)
    return _joined([x * scale, y * scale, z * scale], q.shape[:-1])


def rotvec_to_quat(rotvec: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 3) rotation vectors -> (..., 4) unit quaternions with w >= 0."""
    r = np.asarray(rotvec, dtype=np.float64)
    x, y, z = _components(r, 3)
    angle = _length(x, y, z)
    half = 0.5 * angle
    # sin(angle/2) / angle, with its limit 1/2 (- angle^2 / 48) near zero
    scale = np.where(angle > _SMALL, np.sin(half) / np.maximum(angle, _SMALL), 0.5 - angle**2 / 48.0)
    return _joined([np.cos(half), x * scale, y * scale, z * scale], r.shape[:-1])


def quat_multiply(a: ArrayLike, b: ArrayLike) -> npt.NDArray[np.float64]:
    """Hamilton product a b of (..., 4) quaternions (w, x, y, z): the rotation b, then a."""
    aw, ax, ay, az = np.moveaxis(np.asarray(a, dtype=np.float64), -1, 0)
    bw, bx, by, bz = np.moveaxis(np.asarray(b, dtype=np.float64), -1, 0)
    product: npt.NDArray[np.float64] = np.stack(
        [aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
         aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=-1)
    return product


def continuous(quats: ArrayLike) -> npt.NDArray[np.float64]:
    """(N, ..., 4) quaternions with signs flipped so each is on the same hemisphere as the one the frame before.

    Keys are interpolated channel by channel; without this a sign flip between two frames would swing the bone
    the long way round.
    """
    q = np.asarray(quats, dtype=np.float64)
    steps = np.where(np.sum(q[1:] * q[:-1], axis=-1) < 0.0, -1.0, 1.0)  # (N-1, ...)
    signs = np.concatenate([np.ones((1,) + q.shape[1:-1]), np.cumprod(steps, axis=0)])  # (N, ...)
    flipped: npt.NDArray[np.float64] = q * signs[..., None]
    return flipped


def quat_mean(quats: ArrayLike) -> npt.NDArray[np.float64]:
    """(C, ..., 4) -> (..., 4): the normalised mean of C quaternions, each first put on the first one's hemisphere
    (close rotations' mean; rotations far apart, such as out-of-phase waves, average to a nearly still pose)."""
    q = np.asarray(quats, dtype=np.float64)
    q = np.where(np.sum(q * q[:1], axis=-1, keepdims=True) < 0.0, -q, q)
    mean = q.mean(axis=0)
    normalised: npt.NDArray[np.float64] = mean / np.linalg.norm(mean, axis=-1, keepdims=True)
    return normalised


def quat_to_matrix(quat: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 4) quaternions -> (..., 3, 3) rotation matrices (columns are the rotated axes)."""
    q = np.asarray(quat, dtype=np.float64)
    w, x, y, z = _components(q, 4)
    length = _length(w, x, y, z)
    w, x, y, z = w / length, x / length, y / length, z / length
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
    m = _joined([
        1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy),
        2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx),
        2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy),
    ], q.shape[:-1])
    return m.reshape(q.shape[:-1] + (3, 3))


def _picked(picks: Sequence[npt.NDArray[np.bool_]],
            options: Sequence[npt.NDArray[np.float64]]) -> npt.NDArray[np.float64]:
    """Per element, options[0], or options[k + 1] where picks[k] (masks that never overlap)."""
    out = options[0].copy()
    for pick, option in zip(picks, options[1:], strict=True):
        np.copyto(out, option, where=pick)
    return out


def matrix_to_quat(matrix: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 3, 3) rotation matrices -> (..., 4) unit quaternions with w >= 0 (Shepperd's method)."""
    m = np.asarray(matrix, dtype=np.float64)
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = _components(m, 9)
    trace = m00 + m11 + m22
    # Pick the numerically largest of w, x, y, z per matrix (the first on a tie) and derive the rest from it.
    picks = []
    largest = trace
    for diagonal in (m00, m11, m22):
        picks.append(diagonal > largest)
        largest = np.where(picks[-1], diagonal, largest)
    for k in range(2, -1, -1):  # a later pick wins over the ones before it
        for later in picks[k + 1:]:
            picks[k] &= ~later
    r = np.sqrt(_picked(picks, [1.0 + trace, 1.0 + m00 - m11 - m22, 1.0 + m11 - m00 - m22,
                                1.0 + m22 - m00 - m11])) * 2.0
    quarter = 0.25 * r
    d0, d1, d2 = (m21 - m12) / r, (m02 - m20) / r, (m10 - m01) / r
    s01, s02, s12 = (m01 + m10) / r, (m02 + m20) / r, (m12 + m21) / r
    q = [_picked(picks, [quarter, d0, d1, d2]), _picked(picks, [d0, quarter, s01, s02]),
         _picked(picks, [d1, s01, quarter, s12]), _picked(picks, [d2, s02, s12, quarter])]
    flip = q[0] < 0.0
    q = [np.where(flip, -c, c) for c in q]
    length = _length(*q)
    return _joined([c / length for c in q], m.shape[:-2])


def rotvec_to_matrix(rotvec: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 3) rotation vectors -> (..., 3, 3) rotation matrices."""
    return quat_to_matrix(rotvec_to_quat(rotvec))


def matrix_to_rotvec(matrix: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 3, 3) rotation matrices -> (..., 3) rotation vectors."""
    return quat_to_rotvec(matrix_to_quat(matrix))


_AXES = {"X": 0, "Y": 1, "Z": 2}


def _axis_matrix(axis: int, angle: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(..., 3, 3) rotations by angle (...) about coordinate axis 0, 1 or 2."""
    rotvec = np.zeros(np.shape(angle) + (3,))
    rotvec[..., axis] = angle
    return rotvec_to_matrix(rotvec)


def euler_to_matrix(euler: ArrayLike, order: str = "XYZ") -> npt.NDArray[np.float64]:
    """(..., 3) Euler angles in Blender's convention -> (..., 3, 3): order 'XYZ' applies X first (Rz Ry Rx)."""
    e = np.asarray(euler, dtype=np.float64)
    m = np.broadcast_to(np.eye(3), e.shape[:-1] + (3, 3))
    for axis in order:
        m = _axis_matrix(_AXES[axis], e[..., _AXES[axis]]) @ m
    return m


def matrix_to_euler(matrix: ArrayLike, order: str = "XYZ",
                    previous: ArrayLike | None = None) -> npt.NDArray[np.float64]:
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


def quat_to_axis_angle(quat: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 4) quaternions -> (..., 4) Blender axis-angle (angle, x, y, z); continuous quaternions give
    continuous values (the angle runs up to 2 pi rather than flipping the axis)."""
    q = np.asarray(quat, dtype=np.float64)
    sin_half = np.linalg.norm(q[..., 1:], axis=-1)
    angle = 2.0 * np.arctan2(sin_half, q[..., 0])
    axis = np.where(sin_half[..., None] > _SMALL, q[..., 1:] / np.maximum(sin_half, _SMALL)[..., None], [0.0, 1.0, 0.0])
    return np.concatenate([angle[..., None], axis], axis=-1)


def rotation_part(matrices: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(..., 3, 3) rotations of (..., 4, 4) matrices, scale removed."""
    rotation = matrices[..., :3, :3]
    unscaled: npt.NDArray[np.float64] = rotation / np.linalg.norm(rotation, axis=-2, keepdims=True)
    return unscaled
