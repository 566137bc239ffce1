"""Blender's NLA in plain numpy: which strip of a track plays at each frame, at what time of its action and with
what influence, and how a strip's values blend into those below (Replace and Combine).

As Blender evaluates it (anim_sys.cc, nla.cc): a track plays the strip the frame falls in; between strips the
one before holds (HOLD, HOLD_FORWARD) until the next starts, before the first strip the first one holds only
with HOLD, after the last the last one holds unless NOTHING; a held strip plays its first or last frame. Its
influence ramps over its blend in, then its blend out, from the frame it plays (so a held strip with a blend
out adds nothing). A channel that some strip of a playing track keys starts from its default value (the
property's: 0, a scale of 1, the identity rotation) and each strip blends in what it keys, bottom track first;
Replace mixes by the influence, Combine adds (location, Euler), multiplies (scale: by key^influence) or turns
(quaternions: below @ key^influence, each normalized first).
"""
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

#: Each channel's default value (the property's): what a channel some strip keys starts from.
DEFAULTS = {"location": (0.0, 0.0, 0.0), "scale": (1.0, 1.0, 1.0), "rotation_euler": (0.0, 0.0, 0.0),
            "rotation_quaternion": (1.0, 0.0, 0.0, 0.0), "rotation_axis_angle": (0.0, 0.0, 1.0, 0.0)}
BLEND_TYPES = ("REPLACE", "COMBINE")


@dataclass(frozen=True)
class Strip:
    """An NLA action strip's timing: where it sits (start, end), the frames of its action it plays (action_start,
    action_end) at what scale and how many times, how it holds outside (extrapolation: HOLD, HOLD_FORWARD or
    NOTHING), its blend in and out (frames), its blend type, whether it is muted; influence: a fixed one
    (the active action's), else None (from the blends)."""
    start: float
    end: float
    action_start: float
    action_end: float
    scale: float = 1.0
    repeat: float = 1.0
    extrapolation: str = "HOLD"
    blend_in: float = 0.0
    blend_out: float = 0.0
    blend_type: str = "REPLACE"
    muted: bool = False
    influence: float | None = None


def playing(strips: Sequence[Strip], frames: Array) -> tuple[npt.NDArray[np.int64], Array]:
    """((N,) index of the strip of a track that plays at each frame (-1: none), (N,) the frame it plays at:
    the frame, or the strip's start or end where it holds). strips: the track's, in time order."""
    index = np.full(len(frames), -1, dtype=np.int64)
    at = np.array(frames, dtype=np.float64)
    decided = np.zeros(len(frames), dtype=bool)
    for k, strip in enumerate(strips):
        within = ~decided & (frames >= strip.start) & (frames <= strip.end)
        index[within] = k
        decided |= within
        before = ~decided & (frames < strip.start)
        held = strips[k - 1] if k else strip
        holds = held.extrapolation == "HOLD" if k == 0 else held.extrapolation != "NOTHING"
        if holds:
            index[before] = k - 1 if k else k
            at[before] = held.end if k else held.start
        decided |= before
    last = len(strips) - 1
    after = ~decided & (frames > strips[last].end) if strips else decided
    if strips and strips[last].extrapolation != "NOTHING":
        index[after] = last
        at[after] = strips[last].end
    muted = np.array([s.muted for s in strips] + [True])  # index -1 reads the last entry: no strip
    index[muted[index]] = -1
    return index, at


def strip_time(strip: Strip, at: Array) -> Array:
    """(N,) the time of the strip's action played at frames `at` (within the strip)."""
    scale = abs(strip.scale) or 1.0
    length = (strip.action_end - strip.action_start) or 1.0
    times = strip.action_start + np.fmod(at - strip.start, length * scale) / scale
    if float(strip.repeat).is_integer():  # the end plays the action's end, not its start again
        times = np.where(at == strip.end, strip.action_end, times)
    return times


def influence(strip: Strip, at: Array) -> Array:
    """(N,) the strip's influence at frames `at` (within it): its fixed influence, else 1 ramped over its blend
    in, then its blend out."""
    if strip.influence is not None:
        return np.full(len(at), float(strip.influence))
    out = np.ones(len(at))
    if strip.blend_out:
        fading = at >= strip.end - strip.blend_out
        out = np.where(fading, np.abs(strip.end - at) / strip.blend_out, out)
    if strip.blend_in:
        rising = at <= strip.start + strip.blend_in
        out = np.where(rising, np.abs(at - strip.start) / strip.blend_in, out)
    return out


def blend(blend_type: str, channel: str, lower: Array, value: Array, weight: Array,
          keyed: npt.NDArray[np.bool_]) -> Array:
    """(N, C) the channel's values after a strip's (N, C) values blend over `lower` with influence (N,) on the
    components `keyed` (C,). A Combine quaternion needs all four components keyed (`combinable`)."""
    weight = weight[:, None]
    if blend_type == "REPLACE":
        mixed = lower * (1.0 - weight) + value * weight
    elif channel == "rotation_quaternion":
        mixed = _combine_quaternions(lower, value, weight[:, 0])
    elif channel == "scale":
        mixed = lower * np.power(value, weight)
    else:
        mixed = lower + value * weight
    return np.where(keyed & (weight > 0.0), mixed, lower)  # a strip without influence adds nothing


def combinable(channel: str, keyed: npt.NDArray[np.bool_]) -> bool:
    """Whether a Combine strip keying the components `keyed` of a channel blends as `blend` does: a
    quaternion keyed whole (Blender treats one keyed in part otherwise), any other channel but axis-angle."""
    return channel != "rotation_axis_angle" and (channel != "rotation_quaternion" or bool(keyed.all()))


def _combine_quaternions(lower: Array, value: Array, weight: Array) -> Array:
    """(N, 4) Blender's nla_combine_quaternion: normalize(lower) @ normalize(value)^weight, in single precision as
    Blender computes it (so a turn below about 3e-4 radians keyed at full influence plays as none, as there)."""
    lower32, value32 = _normalized(lower.astype(np.float32)), _normalized(value.astype(np.float32))
    angle = weight.astype(np.float32) * np.arccos(np.clip(value32[:, 0], np.float32(-1.0), np.float32(1.0)))
    axis = value32[:, 1:]
    length = np.sqrt(np.sum(axis * axis, axis=-1))
    scale = np.where(length * length > np.float32(1e-35), np.sin(angle) / np.where(length > 0, length, 1), 0)
    turned = np.concatenate([np.cos(angle)[:, None], axis * scale.astype(np.float32)[:, None]], axis=-1)
    return _multiply32(lower32, turned).astype(np.float64)


def _normalized(quats: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """Blender's normalize_qt: a zero quaternion becomes (0, 1, 0, 0)."""
    length = np.sqrt(np.sum(quats * quats, axis=-1, keepdims=True))
    zero = np.array([0.0, 1.0, 0.0, 0.0], dtype=np.float32)
    scaled = quats * (np.float32(1.0) / np.where(length != 0, length, np.float32(1.0)))
    return np.where(length != 0, scaled, zero)


def _multiply32(a: npt.NDArray[np.float32], b: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """Blender's mul_qt_qtqt in single precision, term by term in its order."""
    a0, a1, a2, a3 = a.T
    b0, b1, b2, b3 = b.T
    return np.stack([a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3, a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
                     a0 * b2 + a2 * b0 + a3 * b1 - a1 * b3, a0 * b3 + a3 * b0 + a1 * b2 - a2 * b1], axis=-1)
