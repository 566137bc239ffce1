"""F-curves evaluated in numpy as Blender evaluates them, all frames of many curves at once: constant, linear
and Bezier keys with constant extrapolation; any other curve (modifiers, other interpolations or extrapolation)
through Blender's own `FCurve.evaluate`, frame by frame.

Blender's Bezier segments are cubic in both the frame and the value: each frame is solved for the curve
parameter by Newton's method on the segment (each handle first shortened to the segment's length, as
Blender's `BKE_fcurve_correct_bezpart` does), all curves' frames at once.
"""
from collections.abc import Sequence
from typing import Any

import bpy
import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import action_adapter

_INTERPOLATION = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items
_CONSTANT, _LINEAR, _BEZIER = (_INTERPOLATION[name].value for name in ("CONSTANT", "LINEAR", "BEZIER"))
#: Newton steps solving a Bezier segment's frame for its curve parameter, from the linear guess.
_NEWTON_STEPS = 8
Array = npt.NDArray[np.float64]


def _fcurve_keys(fcurve: Any) -> tuple[Array, Array, Array, npt.NDArray[np.int32]]:
    """(co (K, 2), right handles (K, 2), left handles (K, 2), interpolation (K,)) of an F-curve."""
    points = fcurve.keyframe_points
    count = len(points)
    arrays = []
    for field in ("co", "handle_right", "handle_left"):
        values = np.empty(2 * count, dtype=np.float32)
        points.foreach_get(field, values)
        arrays.append(values.reshape(count, 2).astype(np.float64))
    return (*arrays, action_adapter.read_enum(points, "interpolation"))


def _numpy_evaluable(fcurve: Any, interpolation: npt.NDArray[np.int32]) -> bool:
    return (not fcurve.modifiers and fcurve.extrapolation == "CONSTANT" and len(interpolation) > 0
            and ((interpolation == _CONSTANT) | (interpolation == _LINEAR) | (interpolation == _BEZIER)).all())


def evaluate_fcurves(fcurves: Sequence[Any], frames: ArrayLike) -> Array:
    """(F, N) values of F-curves at frames (N,), as Blender evaluates them."""
    frames = np.asarray(frames, dtype=np.float64)
    out = np.empty((len(fcurves), len(frames)))
    keys = [_fcurve_keys(fcurve) for fcurve in fcurves]
    plain = [row for row, (fcurve, kept) in enumerate(zip(fcurves, keys, strict=True))
             if _numpy_evaluable(fcurve, kept[3])]
    for row in sorted(set(range(len(fcurves))) - set(plain)):
        out[row] = [fcurves[row].evaluate(float(f)) for f in frames]
    if plain:
        out[plain] = _evaluate_keys([keys[row] for row in plain], frames)
    return out


def _evaluate_keys(keys: list[tuple[Array, Array, Array, npt.NDArray[np.int32]]], frames: Array) -> Array:
    """(C, N) values at frames (N,) of curves given by their keys (`_fcurve_keys`), all curves at once: each
    curve's keys laid end to end, curve after curve, and each frame found among its own curve's keys."""
    counts = np.array([len(kept[0]) for kept in keys])
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])[:, None]  # (C, 1) each curve's first key
    last = first + counts[:, None] - 1
    co, right, left = (np.concatenate([kept[i] for kept in keys]) for i in range(3))
    interpolation = np.concatenate([kept[3] for kept in keys])
    x, y = co[:, 0], co[:, 1]
    low = min(x.min(), frames.min())
    width = max(x.max(), frames.max()) - low + 1.0  # curve c's keys and frames sit in [c, c + 1) widths
    curve = np.arange(len(keys))
    sorted_keys = (x - low) + np.repeat(curve, counts) * width
    found = np.searchsorted(sorted_keys, (frames[None, :] - low) + curve[:, None] * width, side="right") - 1
    k = np.clip(found, first, np.maximum(last - 1, first))  # (C, N) the key each frame's segment starts at
    nxt = np.minimum(k + 1, last)
    span = np.where(x[nxt] > x[k], x[nxt] - x[k], 1.0)
    u = np.clip((frames - x[k]) / span, 0.0, 1.0)
    value = np.where(interpolation[k] == _CONSTANT, y[k], y[k] + u * (y[nxt] - y[k]))
    value = np.where(frames <= x[first], y[first], np.where(frames >= x[last], y[last], value))
    bezier = (interpolation[k] == _BEZIER) & (frames > x[first]) & (frames < x[last])
    if bezier.any():
        value[bezier] = _solve_bezier(np.broadcast_to(frames, value.shape)[bezier], co[k[bezier]],
                                      right[k[bezier]], left[nxt[bezier]], co[nxt[bezier]])
    return value


def _solve_bezier(wanted: Array, p0: Array, p1: Array, p2: Array, p3: Array) -> Array:
    """(S,) the values of Bezier segments (S, 2 points each) at frames `wanted` (S,), all solved at once."""
    # Each handle shortened to reach no further than the segment (BKE_fcurve_correct_bezpart).
    h1, h2 = p0 - p1, p3 - p2
    length = (p3[:, 0] - p0[:, 0])[:, None]
    p1 = p0 - np.minimum(1.0, length / np.maximum(np.abs(h1[:, :1]), 1e-12)) * h1
    p2 = p3 - np.minimum(1.0, length / np.maximum(np.abs(h2[:, :1]), 1e-12)) * h2
    # x(t) and y(t) as cubic polynomials in t: a t^3 + b t^2 + c t + p0.
    c = 3.0 * (p1 - p0)
    b = 3.0 * (p2 - p1) - c
    a = p3 - p0 - c - b
    t = (wanted - p0[:, 0]) / np.maximum(p3[:, 0] - p0[:, 0], 1e-12)  # the linear guess
    for _ in range(_NEWTON_STEPS):  # x(t) rises monotonically once the handles are shortened
        x = ((a[:, 0] * t + b[:, 0]) * t + c[:, 0]) * t + p0[:, 0]
        slope = (3.0 * a[:, 0] * t + 2.0 * b[:, 0]) * t + c[:, 0]
        t = np.clip(t - (x - wanted) / np.maximum(slope, 1e-9), 0.0, 1.0)
    return ((a[:, 1] * t + b[:, 1]) * t + c[:, 1]) * t + p0[:, 1]
