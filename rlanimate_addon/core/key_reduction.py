"""Editable keys: a few Bezier keys per bone that play a per-frame rotation within a tolerance in degrees.

Each kept key gets handles a third of the way to its neighbours along the frame axis, with the slope
of the per-frame values there (central differences). A Bezier segment whose handles sit at a third
and two thirds of it in time is a cubic Hermite curve in time, so `hermite` predicts exactly what
Blender plays. Keys are added greedily where the played rotation strays furthest from the per-frame
one, until it stays within the tolerance on every frame; all channels of a bone share their keys.
"""
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from .rotations import euler_to_matrix, quat_to_matrix, rotvec_to_matrix


def slopes(values: ArrayLike) -> npt.NDArray[np.float64]:
    """(N, C) per-frame slopes of (N, C) values: central differences, one-sided at the ends."""
    gradient: npt.NDArray[np.float64] = np.gradient(np.asarray(values, dtype=np.float64), axis=0)
    return gradient


def hermite(values: ArrayLike, tangents: npt.NDArray[np.float64],
            keys: Sequence[int] | npt.NDArray[np.int_]) -> npt.NDArray[np.float64]:
    """(N, C) values played between the keys (sorted frame indices into values (N, C)), with handles a
    third of the way to the neighbouring keys along the slopes `tangents` (N, C)."""
    values = np.asarray(values, dtype=np.float64)  # (N, C)
    out = values.copy()
    for a, b in zip(keys[:-1], keys[1:], strict=True):
        t = (np.arange(a, b + 1) - a)[:, None] / float(b - a)
        span = float(b - a)
        h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
        h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
        out[a:b + 1] = (h00 * values[a] + h10 * span * tangents[a] + h01 * values[b] + h11 * span * tangents[b])
    return out


def rotation_matrices(mode: str, values: ArrayLike) -> npt.NDArray[np.float64]:
    """(N, 3, 3) rotations that Blender plays from (N, C) channel values in a rotation mode."""
    values = np.asarray(values, dtype=np.float64)
    if mode == "QUATERNION":
        return quat_to_matrix(values)  # Blender normalises quaternions before use
    if mode == "AXIS_ANGLE":
        axis = values[:, 1:] / np.maximum(np.linalg.norm(values[:, 1:], axis=1, keepdims=True), 1e-12)
        return rotvec_to_matrix(axis * values[:, :1])
    return euler_to_matrix(values, mode)


def angles_between(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(N,) degrees between (N, 3, 3) rotations a and b."""
    cos = (np.trace(np.swapaxes(a, -1, -2) @ b, axis1=-2, axis2=-1) - 1.0) / 2.0
    degrees: npt.NDArray[np.float64] = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    return degrees


def reduce_keys(mode: str, values: ArrayLike, tolerance_deg: float,
                offset: ArrayLike | None = None) -> tuple[npt.NDArray[np.int_], float]:
    """(kept frame indices (K,), worst deviation in degrees) for one bone's (N, C) rotation channels.

    offset: (N, C) values the channels are added to when played (an Euler or axis-angle Combine layer
    over the animation underneath), so the deviation is measured on the rotation that plays.
    """
    values = np.asarray(values, dtype=np.float64)
    base = 0.0 if offset is None else np.asarray(offset, dtype=np.float64)
    target = rotation_matrices(mode, values + base)
    tangents = slopes(values)
    keys = [0, len(values) - 1]
    while True:
        error = angles_between(target, rotation_matrices(mode, hermite(values, tangents, keys) + base))
        worst = int(np.argmax(error))
        if error[worst] <= tolerance_deg or worst in keys:
            return np.array(keys), float(error.max())
        keys = sorted(keys + [worst])
