"""Timing."""

import numpy as np

from rlanimate_addon.core.easing import minimum_jerk
from rlanimate_addon.core.rotations import matrix_to_rotvec, rotvec_to_matrix

from .pose import REST_LOCAL


def keyed_progress(times, knots):
    """Progress at `times` (T,) through (time, value) knots, minimum-jerk between consecutive knots:
    every knot is reached at rest, so the curve is smooth (C2) and each segment's speed one bell."""
    out = np.full(np.shape(times), float(knots[0][1]))
    for (t0, v0), (t1, v1) in zip(knots[:-1], knots[1:], strict=True):
        inside = times >= t0
        out = np.where(inside, v0 + (v1 - v0) * minimum_jerk((times - t0) / max(t1 - t0, 1e-9)), out)
    return out


def blend_rotation(name, start, end, progress):
    """Local rotations (T, 3, 3) of bone `name` from start (3, 3) to end ((T,) 3, 3) at progress (T,),
    which may leave [0, 1] for anticipation and overshoot. The bone's direction moves along a great
    circle while its roll turns evenly (swing-twist), so no bone wobbles off its path."""
    rest = REST_LOCAL[name]
    first, last = rest @ start, rest @ end  # orientations in the parent's frame
    y0, y1 = first[..., :, 1], last[..., :, 1]
    axis = np.cross(y0, y1)
    sine = np.linalg.norm(axis, axis=-1)
    angle = np.arctan2(sine, np.sum(y0 * y1, axis=-1))
    axis = axis / np.maximum(sine, 1e-12)[..., None]
    swung = rotvec_to_matrix(axis * angle[..., None]) @ first  # direction of `last`, roll of `first`
    twist = np.sum(matrix_to_rotvec(last @ np.swapaxes(swung, -1, -2)) * y1, axis=-1)
    progress = np.asarray(progress)
    swing = rotvec_to_matrix(axis * (progress * angle)[..., None])
    direction = (swing @ y0[..., None])[..., 0]
    return rest.T @ (rotvec_to_matrix(direction * (progress * twist)[..., None]) @ swing @ first)
