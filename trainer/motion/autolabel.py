"""Labels from motion, for clips that come without them (real capture, a user's own takes).

Everything is measured on the canonical rig (numpy FK of the clip's (F, 15, 3) action rotations,
trainer/motion/fk.py), relative to the shoulder and in arm lengths L (rest shoulder-to-wrist distance),
so the labels do not depend on the actor's height or where they stood.

Arm: the one whose wrist travels further relative to its shoulder ("which hand moves more").

Wave exaggeration in [0, 1], from how high the arm goes and how wide the hand strokes:
    elevation_t  = angle between shoulder->wrist and straight down (0 hanging, 90 level, 180 overhead)
    elevation    = ELEVATION_PERCENTILE-th percentile of elevation_t over the clip (the raised arm)
    raised       = frames with elevation_t >= low + RAISED_SHARE * (elevation - low), low = min elevation_t
    stroke       = 2 sqrt(2) RMS over `raised` of (wrist - shoulder) minus its centred moving average
                   over STROKE_WINDOW_S seconds, divided by L (peak-to-peak of a sinusoidal wave)
    exaggeration = clip(ELEVATION_WEIGHT * e + STROKE_WEIGHT * s, 0, 1), with
                   e = clip((elevation - ELEVATION_LOW) / (ELEVATION_HIGH - ELEVATION_LOW), 0, 1)
                   s = clip(stroke / STROKE_FULL, 0, 1)
The constants were set on the real capture (docs/REALMOCAP.md): a small, low, bent-armed wave (wrist
about 80 deg up, strokes of 0.1 L) labels near 0.1, a straight overhead wave with strokes of 0.45 L
near 0.75, and one with whole-arm sweeps wider than L near 1.

Another intensity behaviour (raise a hand, or one of the user's own): how high the arm goes, the
ELEVATION_PERCENTILE-th percentile of elevation_t, which a capture folder's labels place between the lowest
and highest takes of the behaviour (trainer/motion/capture_folder.py).

Pointing direction: at the hold (the stillest frame while the arm is raised), the unit vector from the
arm's rest shoulder to the index-finger base, i.e. the objective `spaces.pointing_direction` whose
ray the finger base lies on.

A take's behaviour comes from its names (`behaviour_from_name`): a known behaviour's word in its file name, else
the name of the folder that holds it.
"""
import re
from collections import namedtuple
from pathlib import Path

import numpy as np

from rlanimate_addon.core import behaviours, frame_rate, kinematics, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion import fk

ELEVATION_PERCENTILE = 90
RAISED_SHARE = 0.8
STROKE_WINDOW_S = 0.5
ELEVATION_LOW, ELEVATION_HIGH = 60.0, 170.0  # degrees
STROKE_FULL = 1.0  # arm lengths, peak to peak
ELEVATION_WEIGHT, STROKE_WEIGHT = 0.6, 0.4

#: arm 'LEFT'/'RIGHT'; exaggeration in [0, 1]; elevation in degrees; stroke in arm lengths;
#: travel {arm: wrist path length in arm lengths}.
WaveLabel = namedtuple("WaveLabel", "arm exaggeration elevation stroke travel")
#: arm; direction (3,) unit vector from the rest shoulder to the index base; hold_frame index.
PointLabel = namedtuple("PointLabel", "arm direction hold_frame")

_SIDES = {"LEFT": "Left", "RIGHT": "Right"}
#: The behaviours a take's file name can name by a word of it, with their kinds: the paper's pair and the
#: sample library's other two (docs/CLIPS.md).
NAMED_BEHAVIOURS = {**behaviours.KNOWN_KINDS, "GUIDE": behaviours.TARGET, "RAISE_HAND": behaviours.INTENSITY}


def arm_length(side="Left"):
    """Rest shoulder-to-wrist distance of the canonical rig, metres."""
    shoulder = np.asarray(skeleton.BONE_BY_NAME[side + "Arm"].head)
    return float(np.linalg.norm(np.asarray(skeleton.BONE_BY_NAME[side + "Hand"].head) - shoulder))


def joint_heads(rotvecs, bones):
    """{bone: (F, 3)} head positions, character frame, metres, of a (F, 15, 3) action clip."""
    heads = fk.bone_heads(_checked(rotvecs))  # (F, B, 3)
    return {bone: heads[:, kinematics.bone_index(bone)] for bone in bones}


def _checked(rotvecs):
    r = np.asarray(rotvecs, dtype=np.float64)
    joints = len(skeleton.ACTION_JOINTS)
    if r.ndim != 3 or r.shape[1:] != (joints, 3) or len(r) < 2:
        raise RLAnimateError(f"Auto-labelling needs a clip of shape (frames >= 2, {joints}, 3), got {r.shape}.")
    if not np.all(np.isfinite(r)):
        raise RLAnimateError("The clip has NaN or infinite rotations: re-import it before labelling.")
    return r


def _arm_vectors(rotvecs):
    """{arm: (F, 3) wrist minus shoulder, in arm lengths}."""
    bones = [s + b for s in _SIDES.values() for b in ("Arm", "Hand")]
    heads = joint_heads(rotvecs, bones)
    return {arm: (heads[side + "Hand"] - heads[side + "Arm"]) / arm_length(side) for arm, side in _SIDES.items()}


def _travel(vectors):
    return float(np.linalg.norm(np.diff(vectors, axis=0), axis=-1).sum())


def _elevation(vectors):
    """(F,) degrees between each shoulder->wrist vector and straight down."""
    unit = vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)
    return np.degrees(np.arccos(np.clip(-unit[:, 2], -1.0, 1.0)))


def _raised(elevation_t, elevation):
    low = float(np.min(elevation_t))
    return elevation_t >= low + RAISED_SHARE * (elevation - low)


def raised_frames(rotvecs, arm):
    """(F,) bool: the frames where `arm` ('LEFT'/'RIGHT') is raised, as the wave label reads them."""
    elevation_t = _elevation(_arm_vectors(rotvecs)[arm])
    return _raised(elevation_t, float(np.percentile(elevation_t, ELEVATION_PERCENTILE)))


def _moving_average(values, window):
    """Centred moving average along axis 0 of (F, D), with edge padding."""
    half = window // 2
    padded = np.pad(values, ((half, half), (0, 0)), mode="edge")
    kernel = np.ones(2 * half + 1) / (2 * half + 1)
    return np.stack([np.convolve(padded[:, d], kernel, mode="valid") for d in range(values.shape[1])], axis=1)


def moving_arm(rotvecs):
    """'LEFT' or 'RIGHT': the arm whose wrist travels further relative to its shoulder."""
    return _moving(_arm_vectors(rotvecs))


def _moving(vectors):
    """'LEFT' or 'RIGHT': the arm of _arm_vectors' {arm: vectors} whose wrist travels further."""
    return max(vectors, key=lambda arm: _travel(vectors[arm]))


def label_wave(rotvecs, fps=frame_rate.AGENT_FPS):
    """WaveLabel of a (F, 15, 3) waving clip (see the module docstring for the formula)."""
    vectors = _arm_vectors(rotvecs)
    travel = {arm: _travel(v) for arm, v in vectors.items()}
    arm = max(travel, key=travel.get)
    elevation_t = _elevation(vectors[arm])
    elevation = float(np.percentile(elevation_t, ELEVATION_PERCENTILE))
    raised = _raised(elevation_t, elevation)
    window = max(3, int(round(STROKE_WINDOW_S * float(fps))) | 1)
    residual = vectors[arm] - _moving_average(vectors[arm], window)  # (F, 3)
    stroke = float(2.0 * np.sqrt(2.0) * np.sqrt(np.mean(np.sum(residual[raised] ** 2, axis=-1))))
    e = np.clip((elevation - ELEVATION_LOW) / (ELEVATION_HIGH - ELEVATION_LOW), 0.0, 1.0)
    s = np.clip(stroke / STROKE_FULL, 0.0, 1.0)
    exaggeration = float(np.clip(ELEVATION_WEIGHT * e + STROKE_WEIGHT * s, 0.0, 1.0))
    return WaveLabel(arm, exaggeration, elevation, stroke, travel)


def label_point(rotvecs, arm=None):
    """PointLabel of a (F, 15, 3) pointing or directing clip; `arm` defaults to the moving arm."""
    arm = arm or moving_arm(rotvecs)
    side = _SIDES[arm]
    heads = joint_heads(rotvecs, [side + "Arm", side + "Hand", side + "HandIndex1"])
    vectors = (heads[side + "Hand"] - heads[side + "Arm"]) / arm_length(side)
    elevation_t = _elevation(vectors)
    raised = _raised(elevation_t, float(np.max(elevation_t)))
    speed = np.linalg.norm(np.gradient(vectors, axis=0), axis=-1)  # (F,) arm lengths per frame
    speed = _moving_average(speed[:, None], 5)[:, 0]
    hold = int(np.flatnonzero(raised)[np.argmin(speed[raised])])
    direction = spaces.pointing_direction(arm, heads[side + "HandIndex1"][hold])
    return PointLabel(arm, direction, hold)


def name_words(path) -> list[str]:
    """The lower-case words of a file name's stem ("dataset-2_wave-left-hand_active_001" -> dataset, 2, wave, ...)."""
    return [word for word in re.split(r"[^a-z0-9]+", Path(path).stem.lower()) if word]


def behaviour_from_name(path) -> str:
    """The behaviour id a take's names give: a NAMED_BEHAVIOURS word in its file name ("wave_left_003.fbx",
    "raise_hand_right_001.bvh"), else the name of the folder that holds it ("hello/take_001.bvh" -> HELLO);
    RLAnimateError naming the fix when that folder's name is no behaviour name."""
    joined = "_" + "_".join(name_words(path)) + "_"
    named = [name for name in NAMED_BEHAVIOURS if f"_{name.lower()}_" in joined]
    if named:
        return max(named, key=len)  # raise_hand, not a shorter name inside it
    folder = Path(path).parent.name
    try:
        return behaviours.parse(folder)
    except RLAnimateError:
        words = ", ".join(b.lower() for b in NAMED_BEHAVIOURS)
        raise RLAnimateError(f"{path}: its name has no behaviour's word ({words}) and its folder's name {folder!r} is "
                             f"no behaviour name: put the takes of each gesture in a folder named for it (hello/, "
                             f"this_way/), or name the files for it.") from None


def arm_from_name(path) -> str | None:
    """'LEFT' or 'RIGHT' when exactly one of those words is in the file name, else None."""
    named = {word.upper() for word in name_words(path)} & set(skeleton.ARMS)
    return named.pop() if len(named) == 1 else None


def arm_elevation(rotvecs, arm=None) -> tuple[str, float]:
    """(arm, degrees): the moving arm (or `arm`) and how high it goes, the ELEVATION_PERCENTILE-th percentile
    of its elevation_t: the measure an intensity behaviour other than WAVE is labelled by."""
    vectors = _arm_vectors(rotvecs)
    arm = arm or _moving(vectors)
    return arm, float(np.percentile(_elevation(vectors[arm]), ELEVATION_PERCENTILE))


#: Metres: a behaviour's free arm has no part in it when, in its median training clip, that arm's wrist strays at
#: most this far from where it stood at the first frame (moved by its own joints alone): the add-on then holds
#: it where it was (core/gesture.py).
FREE_ARM_STILL = 0.05


def free_arm_shift(rotvecs, arm) -> float:
    """Metres: the farthest the wrist of the arm other than `arm` strays from its first frame's place, moved by that
    arm's own joints alone (collar to index base; the spine held at its first frame)."""
    r = _checked(rotvecs)
    side = _SIDES["RIGHT" if arm == "LEFT" else "LEFT"]
    free = [k for k, name in enumerate(skeleton.ACTION_JOINTS) if name.startswith(side)]
    moved = np.repeat(r[:1], len(r), axis=0)
    moved[:, free] = r[:, free]
    wrist = joint_heads(moved, [side + "Hand"])[side + "Hand"]  # (F, 3)
    return float(np.linalg.norm(wrist - wrist[0], axis=1).max())


def still_free_arm(clips) -> list[str]:
    """The ids of the behaviours among `clips` (MotionClips with behaviour and arm) whose free arm has no part in
    them: the median free_arm_shift of their clips is at most FREE_ARM_STILL."""
    shifts: dict[str, list[float]] = {}
    for clip in clips:
        shifts.setdefault(clip.behaviour, []).append(free_arm_shift(clip.rotvecs, clip.arm))
    return sorted(b for b, values in shifts.items() if float(np.median(values)) <= FREE_ARM_STILL)


def label_clip(clip, behaviour):
    """Label an unlabelled MotionClip in place from its motion and return it: `behaviour` point or wave,
    either spelling (the user says which; the arm and the attributes come from the motion). This is what
    an `--autolabel` import or training path calls for a user's own clips."""
    behaviour = behaviours.parse(behaviour)
    if behaviour not in behaviours.KNOWN_KINDS:
        raise RLAnimateError(f"Auto-labels read points and waves only, not {behaviour}: label the clips of "
                             f"{behaviour} in a manifest (docs/TRAINING.md, \"Teach it a new gesture\").")
    if behaviours.SHIPPED[behaviour] == behaviours.OSCILLATES:
        label = label_wave(clip.rotvecs, clip.fps)
        clip.behaviour, clip.arm = behaviours.WAVE, label.arm
        clip.exaggeration = clip.attributes = label.exaggeration
    else:
        label = label_point(clip.rotvecs)
        clip.behaviour, clip.arm, clip.attributes = behaviours.POINT, label.arm, label.direction
    clip.label = label
    return clip
