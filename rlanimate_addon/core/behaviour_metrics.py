"""Behaviour metrics: does a generated gesture wave, point, guide ("this way"), raise a hand, raise and lower
the arm like its reference?

The paper's score (core.metrics) is dominated by joints that barely move and leans on each clip's own
timing, so a still arm or a class mean scores close to a real wave. These measures read what an
animator sees. All take joint positions (F, 10, 3) of skeleton.DESCRIPTION_JOINTS in the character
frame (+X the character's left, -Y forward, +Z up, metres), as `spaces.description_joint_positions`
gives them, and the gesturing arm ('LEFT' or 'RIGHT'). Definitions and thresholds: docs/METRICS.md.

Wave, over the *hand-up run*: the longest run of frames whose wrist is at most HAND_UP_DROP arm
lengths below the same arm's shoulder joint. The side-to-side coordinate is the wrist's X relative to
that shoulder; a *stroke* is one leg between turning points of it found with hysteresis
STROKE_FRACTION x shoulder width (each stroke moves at least that far); a full cycle is two strokes.
Point: the finger line (index base b, unit direction f) against the target T; the *hold* is the
longest run of frames in which b moves slower than HOLD_SPEED shoulder widths per second and is at
least half its largest distance from its first position.
Guide ("this way"), over the same hold: the fingers head towards the target seen from above, the palm
(`palm_normal`) faces up, the wrist is out from the shoulder. Raise hand: held with the hand up and the
wrist still, the forearm near vertical, no side-to-side strokes beyond the raise and the lowering, and
the wrist as high above the shoulder as the reference's. Each is a behaviour's by what it does
(core/behaviours.py: point, wave, present, raise; `MEASURES`). A behaviour that does none of these (a user's
gesture declaring nothing) is measured by its kind (`KIND_MEASURES`): an intensity one by the hand's peak
height, a target one by its aim at the target, each with the other arm's rise.
"""
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import behaviours, metrics, skeleton, spaces
from .errors import RLAnimateError
from .frame_rate import AGENT_FPS

#: The hand is up while the wrist is at most this many arm lengths below its shoulder joint.
HAND_UP_DROP = 0.25
#: A stroke moves the wrist side to side by at least this share of the shoulder width (the issue's 8%).
STROKE_FRACTION = 0.08
#: The pointing hold: the finger base moves slower than this many shoulder widths per second ...
HOLD_SPEED = 0.25
#: Sakoe-Chiba band of the time-aligned score, as a share of the longer clip.
DTW_BAND = 0.15

_JOINT = {name: k for k, (name, _) in enumerate(skeleton.DESCRIPTION_JOINTS)}

Array = npt.NDArray[np.float64]
#: (first, last) frame of a run, end inclusive, or None.
Run = tuple[int, int] | None
#: A measure's figures by name.
Measures = dict[str, Any]
#: A behaviour's measures: (generated, reference descriptions (F, 42), arm, target (3,) or None, fps) -> figures.
Measure = Callable[[ArrayLike, ArrayLike, str, ArrayLike | None, float], dict[str, float]]


def _side(arm: str) -> str:
    if arm not in skeleton.ARMS:
        raise RLAnimateError(f"Unknown arm {arm!r}: use LEFT or RIGHT.")
    return arm.lower()


def _positions(positions: ArrayLike, name: str = "The clip") -> Array:
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] != (len(skeleton.DESCRIPTION_JOINTS), 3) or len(p) < 2:
        raise RLAnimateError(f"{name} must be description-joint positions of shape (frames >= 2, "
                             f"{len(skeleton.DESCRIPTION_JOINTS)}, 3), got {p.shape}.")
    if not np.all(np.isfinite(p)):
        raise RLAnimateError(f"{name} contains NaN or infinite positions: regenerate it.")
    return p


def finger_direction(descriptions: ArrayLike, arm: str) -> Array:
    """(F, 3) unit index-finger direction (base to tip) of the arm, from descriptions (F, 42)."""
    effectors = np.asarray(descriptions)[..., spaces.DESCRIPTION_EFFECTORS]
    row = [name for name, _, _ in skeleton.EFFECTORS].index(f"{_side(arm)}_index")
    return effectors[..., 3 * row:3 * row + 3]


def joint(positions: ArrayLike, name: str) -> Array:
    """(F, 3) path of one description joint, e.g. 'right_wrist'."""
    return _positions(positions)[:, _JOINT[name]]


def shoulder_width(positions: ArrayLike) -> float:
    """Distance (m) between the two shoulder joints in the first frame: the scale of the thresholds."""
    p = _positions(positions)
    return float(np.linalg.norm(p[0, _JOINT["left_shoulder"]] - p[0, _JOINT["right_shoulder"]]))


def arm_length(positions: ArrayLike, arm: str) -> float:
    """Shoulder-elbow plus elbow-wrist length (m) in the first frame."""
    p, side = _positions(positions), _side(arm)
    shoulder, elbow, wrist = (p[0, _JOINT[f"{side}_{j}"]] for j in ("shoulder", "elbow", "wrist"))
    return float(np.linalg.norm(elbow - shoulder) + np.linalg.norm(wrist - elbow))


def elevation(positions: ArrayLike, arm: str) -> Array:
    """(F,) arm elevation in degrees: the angle of the upper arm (shoulder to elbow) from straight
    down; 0 hanging, 90 horizontal, 180 straight up."""
    p, side = _positions(positions), _side(arm)
    upper = p[:, _JOINT[f"{side}_elbow"]] - p[:, _JOINT[f"{side}_shoulder"]]
    cosine = -upper[:, 2] / np.linalg.norm(upper, axis=1)
    result: Array = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    return result


def longest_run(mask: ArrayLike) -> Run:
    """(first, last) frame of the longest run of True in a (F,) mask, end inclusive; None if none."""
    mask = np.asarray(mask, dtype=bool)
    if not mask.any():
        return None
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, stops = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    k = int(np.argmax(stops - starts))
    return int(starts[k]), int(stops[k] - 1)


def hand_up_run(positions: ArrayLike, arm: str) -> Run:
    """(first, last) frame of the hand-up run (see the module docstring), or None."""
    p, side = _positions(positions), _side(arm)
    drop = p[:, _JOINT[f"{side}_shoulder"], 2] - p[:, _JOINT[f"{side}_wrist"], 2]  # (F,) m below shoulder
    return longest_run(drop <= HAND_UP_DROP * arm_length(p, arm))


def turning_points(signal: ArrayLike, threshold: float) -> list[int]:
    """Frame indices of the pivots of a zig-zag through a (F,) signal with hysteresis `threshold`:
    the start of the first leg, every turning point, and the end of the last leg. Consecutive pivots
    differ by at least `threshold`; fewer than 2 pivots (an empty list) means no leg that long."""
    x = np.asarray(signal, dtype=np.float64)
    low = high = 0
    direction, extreme, pivots = 0, 0, []
    for i in range(1, len(x)):
        if direction == 0:
            low = i if x[i] < x[low] else low
            high = i if x[i] > x[high] else high
            if x[high] - x[low] >= threshold:
                start, extreme = (low, high) if high > low else (high, low)
                direction = 1 if high > low else -1
                pivots = [start]
        elif direction * (x[i] - x[extreme]) > 0:
            extreme = i
        elif direction * (x[extreme] - x[i]) >= threshold:
            pivots.append(extreme)
            direction, extreme = -direction, i
    return pivots + [extreme] if direction else []


def _refined(signal: Array, frames: Sequence[int]) -> Array:
    """Sub-frame times of extrema at interior `frames` of a (F,) signal: the vertex of the parabola
    through each extremum and its two neighbours (the frame itself at the signal's ends)."""
    times = np.asarray(frames, dtype=np.float64)
    for k, i in enumerate(frames):
        if 0 < i < len(signal) - 1:
            before, at, after = signal[i - 1:i + 2]
            curvature = before - 2.0 * at + after
            times[k] += 0.5 * (before - after) / curvature if curvature else 0.0
    return times


def wave_measures(positions: ArrayLike, arm: str, fps: float = AGENT_FPS) -> Measures:
    """What a wave shows, in absolute units:
    {'hand_up_s', 'strokes', 'cycles', 'swing' (m, the median stroke between two turning points, of
    any stroke with fewer than 3; the run's side-to-side range when there is no stroke), 'frequency'
    (Hz, 0 with fewer than 2 strokes), 'hand_height' (m, the 90th percentile over all frames of the
    wrist's height above where a hanging arm's wrist would be)}."""
    p, side = _positions(positions), _side(arm)
    wrist, shoulder = p[:, _JOINT[f"{side}_wrist"]], p[:, _JOINT[f"{side}_shoulder"]]
    length = arm_length(p, arm)
    hand_height = float(np.percentile(wrist[:, 2] - shoulder[:, 2] + length, 90))
    run = hand_up_run(p, arm)
    if run is None:
        return {"hand_up_s": 0.0, "strokes": 0, "cycles": 0, "swing": 0.0, "frequency": 0.0,
                "hand_height": hand_height}
    sideways = (wrist[:, 0] - shoulder[:, 0])[run[0]:run[1] + 1]  # (R,)
    pivots = turning_points(sideways, STROKE_FRACTION * shoulder_width(p))
    strokes = max(len(pivots) - 1, 0)
    turns = pivots[1:-1] if strokes >= 3 else pivots  # the run's ends need not be turning points
    legs = np.abs(np.diff(sideways[turns])) if strokes else np.ptp(sideways, keepdims=True)
    half_period_s = np.median(np.diff(_refined(sideways, turns))) / fps if strokes >= 2 else np.inf
    return {"hand_up_s": (run[1] - run[0] + 1) / fps, "strokes": strokes, "cycles": strokes // 2,
            "swing": float(np.median(legs)),
            "frequency": float(0.5 / half_period_s), "hand_height": hand_height}


def ratio(value: float, reference: float) -> float:
    """value / reference; NaN when the reference is 0 (nothing to compare with)."""
    return float(value) / float(reference) if reference else float("nan")


def compare_wave(generated: ArrayLike, reference: ArrayLike, arm: str, fps: float = AGENT_FPS) -> Measures:
    """Wave measures of both clips and the generated one's ratios to the reference:
    {'generated': {...}, 'reference': {...}, 'swing_ratio', 'stroke_ratio', 'frequency_ratio',
    'hand_height_ratio'}."""
    gen, ref = wave_measures(generated, arm, fps), wave_measures(reference, arm, fps)
    return {"generated": gen, "reference": ref,
            "swing_ratio": ratio(gen["swing"], ref["swing"]),
            "stroke_ratio": ratio(gen["strokes"], ref["strokes"]),
            "frequency_ratio": ratio(gen["frequency"], ref["frequency"]),
            "hand_height_ratio": ratio(gen["hand_height"], ref["hand_height"])}


def pointing_angles(finger_base: ArrayLike, finger_direction: ArrayLike, target: ArrayLike) -> Array:
    """(F,) degrees between the finger line (base (F, 3), direction (F, 3)) and the line from the base
    to the target (3,) or (F, 3): 0 when the finger points straight at the target."""
    base = np.asarray(finger_base, dtype=np.float64)
    direction = np.asarray(finger_direction, dtype=np.float64)
    to_target = np.asarray(target, dtype=np.float64) - base
    cosine = np.sum(direction * to_target, axis=-1) / (
        np.linalg.norm(direction, axis=-1) * np.linalg.norm(to_target, axis=-1))
    result: Array = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    return result


def hold_frames(base: Array, width: float, fps: float = AGENT_FPS) -> Run:
    """(first, last) frame of the pointing hold of index-base positions (F, 3) on a character whose
    shoulders are `width` apart (any units, the positions'), or None for a finger that never slows down
    past half its travel; a still arm holds throughout."""
    base = np.asarray(base, dtype=np.float64)
    travel = np.linalg.norm(base - base[0], axis=1)
    speed = np.linalg.norm(np.gradient(base, axis=0), axis=1) * fps  # (F,) units per second
    return longest_run((speed <= HOLD_SPEED * width) & (travel >= 0.5 * travel.max()))


def hold_run(positions: ArrayLike, arm: str, fps: float = AGENT_FPS) -> Run:
    """(first, last) frame of the pointing hold (see the module docstring) of a gesture's description
    joint positions, or None."""
    p, side = _positions(positions), _side(arm)
    return hold_frames(p[:, _JOINT[f"{side}_index_base"]], shoulder_width(p), fps)


def point_measures(positions: ArrayLike, finger_direction: ArrayLike, arm: str, target: ArrayLike,
                   fps: float = AGENT_FPS) -> Measures:
    """{'angle' (degrees, median over the hold of `pointing_angles`), 'hold_s'} of a pointing
    gesture; finger_direction (F, 3): the arm's index-finger direction (base to tip) per frame."""
    p, side = _positions(positions), _side(arm)
    hold = hold_run(p, arm, fps)
    base = p[:, _JOINT[f"{side}_index_base"]]  # (F, 3)
    angles = pointing_angles(base, finger_direction, target)  # (F,)
    if hold is None:  # no hold: the angle at the apex, where the finger base is farthest out
        return {"angle": float(angles[np.argmax(np.linalg.norm(base - base[0], axis=1))]), "hold_s": 0.0}
    first, last = hold
    angles = angles[first:last + 1]
    return {"angle": float(np.median(angles)), "hold_s": (last - first + 1) / fps}


def palm_normal(descriptions: ArrayLike, arm: str) -> Array:
    """(F, 3) unit normal out of the arm's palm, from descriptions (F, 42): the palm's plane holds the
    wrist, the index base and the index direction (on a human hand the index base sits to the thumb
    side of the wrist's line, 14 degrees off the finger on the sample rig), so no hand rotation is needed."""
    positions = spaces.description_joint_positions(np.asarray(descriptions, dtype=np.float64))
    side, sign = _side(arm), 1.0 if arm == "LEFT" else -1.0
    across = positions[..., _JOINT[f"{side}_index_base"], :] - positions[..., _JOINT[f"{side}_wrist"], :]
    normal = -sign * np.cross(across, finger_direction(descriptions, arm))
    result: Array = normal / np.linalg.norm(normal, axis=-1, keepdims=True)
    return result


def _degrees_between(a: ArrayLike, b: ArrayLike) -> Array:
    """(F,) degrees between the vectors a (F, 3) and b ((F,) 3)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    cosine = np.sum(a * b, axis=-1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    result: Array = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    return result


def free_arm_rise(positions: ArrayLike, arm: str) -> float:
    """How far (in its own arm lengths) the *other* arm's wrist rises above its first frame at its highest:
    near 0 when only `arm` gestures, about 1 when both hands go up."""
    p = _positions(positions)
    other = "RIGHT" if _side(arm) == "left" else "LEFT"
    wrist = p[:, _JOINT[f"{other.lower()}_wrist"], 2]
    return float((wrist.max() - wrist[0]) / arm_length(p, other))


#: A one-armed gesture leaves the other arm down: its wrist rises at most this many arm lengths.
FREE_ARM_RISE = 0.1


def _hold_or_apex(p: Array, arm: str, fps: float) -> tuple[npt.NDArray[np.int_], float]:
    """(frames, hold_s): the frames of the pointing hold (hold_run) and its length in seconds, or the apex
    alone (the finger base farthest from its start) and 0 when there is no hold."""
    hold = hold_run(p, arm, fps)
    if hold is None:
        base = p[:, _JOINT[f"{_side(arm)}_index_base"]]
        return np.array([int(np.argmax(np.linalg.norm(base - base[0], axis=1)))]), 0.0
    return np.arange(hold[0], hold[1] + 1), (hold[1] - hold[0] + 1) / fps


def guide_measures(positions: ArrayLike, finger_direction: ArrayLike, palm: ArrayLike, arm: str, target: ArrayLike,
                   fps: float = AGENT_FPS) -> Measures:
    """What a "this way" gesture shows, as medians over its hold (the apex without one):
    {'heading_error' (degrees between the finger's and the target's directions seen from above, the
    target's from the first frame's shoulder joint), 'palm_up' (degrees of the palm normal from
    straight up), 'reach' (the wrist's horizontal distance from the shoulder joint, in arm lengths),
    'extension' (shoulder-to-wrist distance in arm lengths), 'hold_s', 'free_arm_rise'}.
    finger_direction, palm: (F, 3) per frame (`finger_direction`, `palm_normal`)."""
    p, side = _positions(positions), _side(arm)
    frames, hold_s = _hold_or_apex(p, arm, fps)
    shoulder, wrist = p[:, _JOINT[f"{side}_shoulder"]], p[:, _JOINT[f"{side}_wrist"]]
    length = arm_length(p, arm)
    to_target = np.asarray(target, dtype=np.float64) - shoulder[0]
    heading = _degrees_between(np.asarray(finger_direction)[frames, :2], to_target[:2])
    palm_up = _degrees_between(np.asarray(palm)[frames], [0.0, 0.0, 1.0])
    offset = (wrist - shoulder)[frames]
    return {"heading_error": float(np.median(heading)), "palm_up": float(np.median(palm_up)),
            "reach": float(np.median(np.linalg.norm(offset[:, :2], axis=1))) / length,
            "extension": float(np.median(np.linalg.norm(offset, axis=1))) / length, "hold_s": hold_s,
            "free_arm_rise": free_arm_rise(p, arm)}


#: A "this way" gesture: the fingers head within GUIDE_HEADING_DEG of the target seen from above, the
#: palm is within GUIDE_PALM_UP_DEG of facing up, the wrist is out GUIDE_REACH arm lengths, held
#: GUIDE_MIN_HOLD_S or more, the other arm left down (FREE_ARM_RISE).
GUIDE_HEADING_DEG = 20.0
GUIDE_PALM_UP_DEG = 65.0
GUIDE_REACH = 0.5
GUIDE_MIN_HOLD_S = 0.4


def guide_accepted(measures: Measures) -> bool:
    """Whether `guide_measures` show a "this way" towards the target (the bounds above)."""
    return bool(measures["heading_error"] <= GUIDE_HEADING_DEG and measures["palm_up"] <= GUIDE_PALM_UP_DEG
                and measures["reach"] >= GUIDE_REACH and measures["hold_s"] >= GUIDE_MIN_HOLD_S
                and measures["free_arm_rise"] <= FREE_ARM_RISE)


def raise_measures(positions: ArrayLike, arm: str, fps: float = AGENT_FPS) -> Measures:
    """What a raised hand shows: {'height' (m of the wrist above the shoulder joint, median over the
    raised hold; the highest frame's without one), 'height_arm' (the same in arm lengths),
    'forearm_from_vertical' (degrees of elbow-to-wrist from straight up, over the same frames),
    'hold_s' (the longest run of frames with the hand up and the wrist slower than HOLD_SPEED shoulder
    widths per second), 'strokes' (side-to-side strokes while the hand is up, as a wave counts them),
    'free_arm_rise'}."""
    p, side = _positions(positions), _side(arm)
    shoulder, elbow, wrist = (p[:, _JOINT[f"{side}_{j}"]] for j in ("shoulder", "elbow", "wrist"))
    length, width = arm_length(p, arm), shoulder_width(p)
    above = wrist[:, 2] - shoulder[:, 2]  # (F,) m
    speed = np.linalg.norm(np.gradient(wrist, axis=0), axis=1) * fps
    hold = longest_run((above >= -HAND_UP_DROP * length) & (speed <= HOLD_SPEED * width))
    frames = np.arange(hold[0], hold[1] + 1) if hold else np.array([int(np.argmax(above))])
    run = hand_up_run(p, arm)
    strokes = 0 if run is None else max(len(turning_points(
        (wrist[:, 0] - shoulder[:, 0])[run[0]:run[1] + 1], STROKE_FRACTION * width)) - 1, 0)
    height = float(np.median(above[frames]))
    return {"height": height, "height_arm": height / length,
            "forearm_from_vertical": float(np.median(_degrees_between((wrist - elbow)[frames], [0.0, 0.0, 1.0]))),
            "hold_s": 0.0 if hold is None else (hold[1] - hold[0] + 1) / fps, "strokes": strokes,
            "free_arm_rise": free_arm_rise(p, arm)}


#: A raised hand: held RAISE_MIN_HOLD_S or more with the wrist above the shoulder, the forearm within
#: RAISE_FOREARM_DEG of vertical, no wave (at most RAISE_MAX_STROKES side-to-side strokes: the raise and
#: the lowering), the height within RAISE_HEIGHT_ERROR arm lengths of the reference's, and the other arm left
#: down (FREE_ARM_RISE).
RAISE_MIN_HOLD_S = 0.5
RAISE_FOREARM_DEG = 30.0
RAISE_MAX_STROKES = 3
RAISE_HEIGHT_ERROR = 0.1


def compare_raise(generated: ArrayLike, reference: ArrayLike, arm: str, fps: float = AGENT_FPS) -> Measures:
    """Raise measures of both clips and the generated one's height error (arm lengths, absolute):
    {'generated': {...}, 'reference': {...}, 'height_error'}."""
    gen, ref = raise_measures(generated, arm, fps), raise_measures(reference, arm, fps)
    return {"generated": gen, "reference": ref, "height_error": abs(gen["height_arm"] - ref["height_arm"])}


def raise_accepted(comparison: Measures) -> bool:
    """Whether a `compare_raise` result raises the hand like its reference (the bounds above)."""
    gen = comparison["generated"]
    return bool(gen["hold_s"] >= RAISE_MIN_HOLD_S and gen["height"] > 0.0
                and gen["forearm_from_vertical"] <= RAISE_FOREARM_DEG and gen["strokes"] <= RAISE_MAX_STROKES
                and comparison["height_error"] <= RAISE_HEIGHT_ERROR and gen["free_arm_rise"] <= FREE_ARM_RISE)


def raise_lower(generated: ArrayLike, reference: ArrayLike, arm: str) -> dict[str, float]:
    """Arm elevation (degrees) at the first and last frames of both clips, and the generated clip's
    differences from the reference: {'first', 'last', 'reference_first', 'reference_last',
    'first_error', 'last_error'} (errors are absolute)."""
    gen, ref = elevation(generated, arm), elevation(reference, arm)
    return {"first": float(gen[0]), "last": float(gen[-1]),
            "reference_first": float(ref[0]), "reference_last": float(ref[-1]),
            "first_error": float(abs(gen[0] - ref[0])), "last_error": float(abs(gen[-1] - ref[-1]))}


def variation(outputs: Sequence[ArrayLike]) -> float:
    """Mean distance (m) between outputs for the same request: over all pairs, the mean over frames
    and joints of the Euclidean distance. outputs: a list of (F, J, 3) of one shape, at least two."""
    clips = [np.asarray(o, dtype=np.float64) for o in outputs]
    if len(clips) < 2 or any(c.shape != clips[0].shape for c in clips):
        raise RLAnimateError("Variation needs at least two outputs of the same length: generate each seed "
                             "with the same frame count.")
    distances = [np.linalg.norm(a - b, axis=-1).mean() for k, a in enumerate(clips) for b in clips[k + 1:]]
    return float(np.mean(distances))


def resample(positions: ArrayLike, frame_count: int) -> Array:
    """(frame_count, ...) positions linearly interpolated in time over the same span."""
    p = np.asarray(positions, dtype=np.float64)
    source = np.linspace(0.0, 1.0, len(p))
    wanted = np.linspace(0.0, 1.0, int(frame_count))
    flat = p.reshape(len(p), -1)
    out = np.stack([np.interp(wanted, source, flat[:, k]) for k in range(flat.shape[1])], axis=1)
    return out.reshape((int(frame_count),) + p.shape[1:])


def score_at_length(generated: ArrayLike, reference: ArrayLike) -> float:
    """The paper's score of a clip generated at its own length (e.g. the class-average length) against
    the reference time-scaled to that length."""
    generated = np.asarray(generated, dtype=np.float64)
    return metrics.score(generated, resample(reference, len(generated)))


def dtw_path(generated: ArrayLike, reference: ArrayLike, band: float = DTW_BAND) -> npt.NDArray[np.int_]:
    """Dynamic time warping of two (F, J, 3) clips under the score's per-frame L1 error -> (P, 2) frame
    pairs from (0, 0) to (F_g - 1, F_r - 1), within a band of `band` x the longer clip around the
    diagonal of normalised time."""
    gen, ref = np.asarray(generated, dtype=np.float64), np.asarray(reference, dtype=np.float64)
    n, m = len(gen), len(ref)
    cost = np.abs(gen[:, None] - ref[None]).sum(axis=(2, 3))  # (N, M)
    rows, cols = np.meshgrid(np.arange(n) / max(n - 1, 1), np.arange(m) / max(m - 1, 1), indexing="ij")
    width = max(band, 1.0 / min(n, m))  # never narrower than one frame of the shorter clip
    cost[np.abs(rows - cols) > width] = np.inf
    total = np.full((n + 1, m + 1), np.inf)
    total[0, 0] = 0.0
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            total[i, j] = cost[i - 1, j - 1] + min(total[i - 1, j - 1], total[i - 1, j], total[i, j - 1])
    path, i, j = [], n, m
    while i > 0 and j > 0:
        path.append((i - 1, j - 1))
        step = np.argmin([total[i - 1, j - 1], total[i - 1, j], total[i, j - 1]])
        i, j = (i - 1, j - 1) if step == 0 else (i - 1, j) if step == 1 else (i, j - 1)
    return np.array(path[::-1])


def aligned_score(generated: ArrayLike, reference: ArrayLike, band: float = DTW_BAND) -> float:
    """The paper's score over the DTW-matched frame pairs (its per-frame errors and penalties, divided
    by the number of pairs): timing differences within the band cost nothing, shape differences do."""
    gen, ref = _positions(generated, "The generated clip"), _positions(reference, "The reference clip")
    path = dtw_path(gen, ref, band)
    errors = metrics.frame_errors(gen[path[:, 0]], ref[path[:, 1]])
    return float(100.0 - (errors.sum() + metrics.frame_penalties(errors).sum()) / len(errors))


#: The issue's acceptance bounds for a wave against its reference: swing ratio, largest frequency
#: error (share of the reference frequency), fewest full cycles while the hand is up.
WAVE_SWING_RATIO = (0.75, 1.33)
WAVE_FREQUENCY_ERROR = 0.2
WAVE_MIN_CYCLES = 2


def wave_accepted(comparison: Measures) -> bool:
    """Whether a `compare_wave` result waves like its reference (the bounds above)."""
    low, high = WAVE_SWING_RATIO
    return bool(low <= comparison["swing_ratio"] <= high
                and abs(comparison["frequency_ratio"] - 1.0) <= WAVE_FREQUENCY_ERROR
                and comparison["generated"]["cycles"] >= WAVE_MIN_CYCLES)


def wave_row(generated: ArrayLike, reference: ArrayLike, arm: str, target: ArrayLike | None,
             fps: float) -> dict[str, float]:
    """A wave's measures (`compare_wave` and `wave_accepted`) of descriptions (F, 42), as a flat dict."""
    waves = compare_wave(spaces.description_joint_positions(generated), spaces.description_joint_positions(reference),
                         arm, fps)
    result = {k: v for k, v in waves.items() if k.endswith("_ratio")}
    result.update({f"{k}": float(v) for k, v in waves["generated"].items()})
    result.update({f"reference_{k}": float(v) for k, v in waves["reference"].items()})
    result["wave_accepted"] = float(wave_accepted(waves))
    return result


def point_row(generated: ArrayLike, reference: ArrayLike, arm: str, target: ArrayLike | None,
              fps: float) -> dict[str, float]:
    """A point's measures (`point_measures` of both, target (3,) in the character frame) as a flat dict."""
    if target is None:
        raise RLAnimateError("Pointing measures need the target position (x, y, z).")
    point, reference_point = (point_measures(spaces.description_joint_positions(d), finger_direction(d, arm), arm,
                                             target, fps) for d in (generated, reference))
    return {"pointing_angle": point["angle"], "hold_s": point["hold_s"],
            "reference_pointing_angle": reference_point["angle"], "reference_hold_s": reference_point["hold_s"],
            "hold_ratio": ratio(point["hold_s"], reference_point["hold_s"])}


def guide_row(generated: ArrayLike, reference: ArrayLike, arm: str, target: ArrayLike | None,
              fps: float) -> dict[str, float]:
    """A guide's measures (`guide_measures` of both, target (3,) in the character frame, and `guide_accepted`)."""
    if target is None:
        raise RLAnimateError("Guiding measures need the target position (x, y, z).")
    guide, reference_guide = (guide_measures(spaces.description_joint_positions(d), finger_direction(d, arm),
                                             palm_normal(d, arm), arm, target, fps) for d in (generated, reference))
    return {**guide, **{f"reference_{k}": v for k, v in reference_guide.items()},
            "hold_ratio": ratio(guide["hold_s"], reference_guide["hold_s"]),
            "guide_accepted": float(guide_accepted(guide))}


def raise_row(generated: ArrayLike, reference: ArrayLike, arm: str, target: ArrayLike | None,
              fps: float) -> dict[str, float]:
    """A raised hand's measures (`compare_raise` and `raise_accepted`) of descriptions (F, 42), as a flat dict."""
    raised = compare_raise(spaces.description_joint_positions(generated), spaces.description_joint_positions(reference),
                           arm, fps)
    return {**{k: float(v) for k, v in raised["generated"].items()},
            **{f"reference_{k}": float(v) for k, v in raised["reference"].items()},
            "height_error": raised["height_error"], "raise_accepted": float(raise_accepted(raised))}


#: The measures of what a behaviour does (behaviours.ACTIONS): measure(generated, reference, arm, target, fps) ->
#: {name: float} from descriptions (F, 42) of a generated clip and its reference (target: (3,) in the character
#: frame for a target behaviour, else None).
MEASURES: dict[str, Measure] = {behaviours.OSCILLATES: wave_row, behaviours.AIMS: point_row,
                                behaviours.PRESENTS: guide_row, behaviours.RAISES: raise_row}


def peak_hand_height(positions: ArrayLike, arm: str) -> float:
    """Arm lengths: how high the arm's wrist goes above its shoulder joint, at its highest frame."""
    p, side = _positions(positions), _side(arm)
    return float((p[:, _JOINT[f"{side}_wrist"], 2] - p[:, _JOINT[f"{side}_shoulder"], 2]).max() / arm_length(p, arm))


def intensity_row(generated: ArrayLike, reference: ArrayLike, arm: str, target: ArrayLike | None,
                  fps: float) -> dict[str, float]:
    """An intensity behaviour's measures where it has none of its own (a user's gesture, such as a raised hand
    named "hello"): what its exaggeration scales, the hand's peak height ('hand_height_error', arm lengths,
    absolute, against the reference's), and the other arm's rise ('free_arm_rise', and the reference's)."""
    gen, ref = spaces.description_joint_positions(generated), spaces.description_joint_positions(reference)
    return {"hand_height_error": abs(peak_hand_height(gen, arm) - peak_hand_height(ref, arm)),
            "free_arm_rise": free_arm_rise(gen, arm), "reference_free_arm_rise": free_arm_rise(ref, arm)}


def aim_error(positions: ArrayLike, arm: str, target: ArrayLike, fps: float = AGENT_FPS) -> float:
    """Degrees between the shoulder joint's line to the index base and its line to `target` (3,), median over the
    hold (the apex without one)."""
    p, side = _positions(positions), _side(arm)
    frames, _ = _hold_or_apex(p, arm, fps)
    shoulder = p[0, _JOINT[f"{side}_shoulder"]]
    base = p[frames, _JOINT[f"{side}_index_base"]]
    return float(np.median(_degrees_between(base - shoulder, np.asarray(target, dtype=np.float64) - shoulder)))


def target_row(generated: ArrayLike, reference: ArrayLike, arm: str, target: ArrayLike | None,
               fps: float) -> dict[str, float]:
    """A target behaviour's measures where it has none of its own: how far off its target it reaches
    ('aim_error', degrees, and the reference's), and the other arm's rise."""
    if target is None:
        raise RLAnimateError("Aim measures need the target position (x, y, z).")
    gen, ref = spaces.description_joint_positions(generated), spaces.description_joint_positions(reference)
    return {"aim_error": aim_error(gen, arm, target, fps), "reference_aim_error": aim_error(ref, arm, target, fps),
            "free_arm_rise": free_arm_rise(gen, arm), "reference_free_arm_rise": free_arm_rise(ref, arm)}


#: The measures of a behaviour without MEASURES of its own, by its kind (a target one needs the target).
KIND_MEASURES: dict[str, Measure] = {behaviours.INTENSITY: intensity_row, behaviours.TARGET: target_row}


def compare(generated: ArrayLike, reference: ArrayLike, behaviour: behaviours.Behaviour | None, arm: str,
            target: ArrayLike | None = None, fps: float = AGENT_FPS) -> dict[str, float]:
    """The behaviour measures of one request, from descriptions (F, 42) of the generated clip and of
    its reference (lengths may differ): raise and lower, and for `behaviour` (a behaviours.Behaviour; None:
    those alone) the MEASURES of what it does, or else those of its kind (KIND_MEASURES; a target behaviour's
    only with its target). A flat dict of floats."""
    gen, ref = np.asarray(generated), np.asarray(reference)
    gen_positions, ref_positions = spaces.description_joint_positions(gen), spaces.description_joint_positions(ref)
    result = {f"elevation_{k}": v for k, v in raise_lower(gen_positions, ref_positions, arm).items()}
    if behaviour is None:
        return result
    if behaviour.does in MEASURES:
        result.update(MEASURES[behaviour.does](gen, ref, arm, target, fps))
    elif behaviour.kind != behaviours.TARGET or target is not None:
        result.update(KIND_MEASURES[behaviour.kind](gen, ref, arm, target, fps))
    return result
