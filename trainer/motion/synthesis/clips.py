"""Clips."""

from dataclasses import dataclass

import numpy as np

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.rotations import matrix_to_rotvec

from .arms import arm_keys, arm_prefix, move_arm, neutral_body
from .guiding import guide_heading, guide_hold
from .pointing import pointing_geometry, pointing_hold
from .pose import ANIMATED_BONES, FINGERS, FPS, OTHER_ARM, Pose
from .raising import raised_hand_pose
from .style import GestureSpec, draw_style
from .timing import blend_rotation, keyed_progress
from .waving import wave_pose

MAX_WAVING = 1.7  # s of oscillation at most, so no clip runs past 4.5 s

#: The behaviours the generator makes: the paper's two and two more (docs/CLIPS.md).
POINT, WAVE, GUIDE, RAISE_HAND = "POINT", "WAVE", "GUIDE", "RAISE_HAND"

_GROUPS = {  # body part -> bones whose timing it sets (the other arm's bones stay neutral)
    "torso": ("Spine", "Spine1", "Spine2"),
    "gaze": ("Neck", "Head"),
    "arm": ("Shoulder",),  # the arm, forearm and hand follow the wrist's path (move_arm)
    "hand": tuple(f"Hand{finger}{k}" for finger in FINGERS for k in (1, 2, 3)
                              if not (finger == "Index" and k > 1)),
}


def _group_bones(group, arm):
    if group == "torso":  # the free arm re-hangs as the torso moves
        return _GROUPS[group] + tuple(arm_prefix(OTHER_ARM[arm]) + b for b in ("Arm", "ForeArm", "Hand"))
    if group == "gaze":
        return _GROUPS[group]
    return tuple(arm_prefix(arm) + b for b in _GROUPS[group])


@dataclass
class GestureClip:
    """A synthesised clip: local rotation vectors per animated bone, and its phases (frame ranges,
    end inclusive), e.g. 'stroke' and 'hold' for POINT, 'raise', 'wave', 'lower' for WAVE."""
    spec: GestureSpec
    rotvecs: dict      # bone name -> (F, 3), for ANIMATED_BONES
    phases: dict       # name -> (first frame, last frame)
    fps: int = FPS

    @property
    def frames(self):
        return len(next(iter(self.rotvecs.values())))

    def action_rotvecs(self):
        """(F, 15, 3) rotation vectors of skeleton.ACTION_JOINTS, in action order."""
        return np.stack([self.rotvecs[j] for j in skeleton.ACTION_JOINTS], axis=1)


def _frames_between(times, start, end):
    inside = np.nonzero((times >= start - 1e-9) & (times <= end + 1e-9))[0]
    return int(inside[0]), int(inside[-1])


def _assemble(spec, end, progress, times, phases, fold=0.0):
    """The clip from neutral to the `end` pose (batch () or (T,)) and back: every bone blends by its
    group's progress; the gesturing arm follows its wrist's path."""
    neutral = neutral_body()
    pose = Pose()
    for name in ANIMATED_BONES:
        start = neutral.local.get(name, np.eye(3))
        group = next((g for g in _GROUPS if name in _group_bones(g, spec.arm)), None)
        if group is None:
            pose.local[name] = np.broadcast_to(start, times.shape + (3, 3))
        else:
            goal = np.broadcast_to(end.local.get(name, np.eye(3)), times.shape + (3, 3))
            pose.local[name] = blend_rotation(name, start, goal, progress[group])
    move_arm(pose, spec.arm, arm_keys(neutral, spec.arm), arm_keys(end, spec.arm),
              progress["arm"], progress["hand"], fold)
    rotvecs = {name: matrix_to_rotvec(pose.local[name]) for name in ANIMATED_BONES}
    phases = {k: _frames_between(times, *v) for k, v in phases.items()}
    return GestureClip(spec, rotvecs, phases)


def _held_gesture(spec, style, end, stroke, hold, phase_names=("stroke", "hold", "return"), fold=0.05):
    """Out to the `end` pose in `stroke` s (tempo included), held still for `hold` s (before tempo), and
    back: the timing of a point, shared by every gesture that holds one pose."""
    k = style.tempo
    lead, wind, settle = style.lead_in, 0.22 * k, 0.28 * k
    back, back_settle, rest = 0.85 * k, 0.3 * k, 0.3
    t1 = lead + wind + stroke
    t2 = t1 + settle + hold * k
    total = t2 + back + back_settle + rest
    times = np.arange(int(round(total * FPS)) + 1) / FPS
    overshoot = style.overshoot
    knots = {
        "gaze": [(0, 0), (lead, 0), (lead + wind + 0.55 * stroke, 1), (t2 - 0.1, 1), (t2 - 0.1 + 0.75 * back, 0)],
        "torso": [(0, 0), (lead + 0.5 * wind, 0), (t1 + 0.05, 1), (t2, 1), (t2 + back, 0)],
        "arm": [(0, 0), (lead, 0), (lead + wind, -style.anticipation), (t1, 1 + overshoot), (t1 + settle, 1),
                (t2, 1), (t2 + back, -0.5 * overshoot), (t2 + back + back_settle, 0)],
        "hand": [(0, 0), (lead + wind, 0), (t1 + 0.15, 1), (t2 + 0.05, 1),
                 (t2 + 0.05 + back, 0)],
    }
    progress = {g: keyed_progress(times, kn) for g, kn in knots.items()}
    out, held, back_name = phase_names
    return _assemble(spec, end, progress, times,
                     {out: (lead + wind, t1), held: (t1 + settle, t2), back_name: (t2, t2 + back)}, fold=fold)


def _synthesise_point(spec, style):
    target = np.asarray(spec.target, dtype=np.float64)
    _, azimuth, elevation, _ = pointing_geometry(spec.arm, target)
    stroke = (0.62 + 0.1 * max(elevation, 0.0) + 0.1 * max(-azimuth, 0.0)) * style.tempo
    return _held_gesture(spec, style, pointing_hold(spec.arm, target, style), stroke, style.hold)


def _synthesise_guide(spec, style):
    target = np.asarray(spec.target, dtype=np.float64)
    _, azimuth, _ = guide_heading(spec.arm, target)
    stroke = (0.65 + 0.1 * max(-azimuth, 0.0) + 0.05 * abs(azimuth)) * style.tempo
    return _held_gesture(spec, style, guide_hold(spec.arm, target, style), stroke, style.hold + 0.15)


def _synthesise_raise(spec, style):
    e = float(spec.exaggeration)
    stroke = (0.65 + 0.1 * e) * style.tempo
    return _held_gesture(spec, style, raised_hand_pose(spec.arm, e, style), stroke, style.hold + 0.1 + 0.15 * e,
                         ("raise", "hold", "lower"), fold=0.1)


def _synthesise_wave(spec, style):
    e = float(spec.exaggeration)
    k = style.tempo
    lead, wind, rise = style.lead_in, 0.15 * k, (0.7 + 0.15 * e) * k
    lower, settle, rest = (0.8 + 0.1 * e) * k, 0.3 * k, 0.25
    frequency = style.wave_frequency - 0.2 * e  # bigger waves swing a little slower
    t_start = lead + wind + rise - 0.15
    t_stop = t_start + min(style.wave_cycles / frequency, MAX_WAVING)
    t_lower = t_stop - 0.1
    total = t_lower + lower + settle + rest
    times = np.arange(int(round(total * FPS)) + 1) / FPS
    envelope = keyed_progress(times, [(0, 0), (t_start, 0), (t_start + 0.3, 1), (t_stop - 0.3, 1), (t_stop, 0)])
    phase = 2 * np.pi * frequency * np.clip(times - t_start, 0.0, None)
    raised = wave_pose(spec.arm, e, style, phase, envelope)
    knots = {
        "gaze": [(0, 0), (lead - 0.05, 0), (lead + wind + 0.6 * rise, 1), (t_lower, 1), (t_lower + 0.7 * lower, 0)],
        "torso": [(0, 0), (lead + 0.1, 0), (lead + wind + rise, 1), (t_lower, 1), (t_lower + lower, 0)],
        "arm": [(0, 0), (lead, 0), (lead + wind, -0.04), (lead + wind + rise, 1), (t_lower, 1),
                (t_lower + lower, -0.02), (t_lower + lower + settle, 0)],
        "hand": [(0, 0), (lead + wind, 0), (lead + wind + 0.85 * rise, 1), (t_lower + 0.1, 1),
                 (t_lower + 0.1 + lower, 0)],
    }
    progress = {g: keyed_progress(times, kn) for g, kn in knots.items()}
    return _assemble(spec, raised, progress, times,
                     {"raise": (lead + wind, t_start), "wave": (t_start, t_stop), "lower": (t_stop, t_lower + lower)},
                     fold=0.08)


#: {behaviour: (kind, synthesiser)}: a target behaviour needs spec.target, an intensity one spec.exaggeration.
SYNTHESISERS = {POINT: ("target", _synthesise_point), WAVE: ("intensity", _synthesise_wave),
                GUIDE: ("target", _synthesise_guide), RAISE_HAND: ("intensity", _synthesise_raise)}


def synthesise(spec):
    """GestureClip for a GestureSpec; raises RLAnimateError for an unusable spec."""
    if spec.behaviour not in SYNTHESISERS:
        raise RLAnimateError(f"Unknown behaviour {spec.behaviour!r}: use {', '.join(SYNTHESISERS)}.")
    if spec.arm not in skeleton.ARMS:
        raise RLAnimateError(f"Unknown arm {spec.arm!r}: use LEFT or RIGHT.")
    kind, synthesiser = SYNTHESISERS[spec.behaviour]
    if kind == "target" and (spec.target is None or np.shape(spec.target) != (3,)):
        raise RLAnimateError(f"A {spec.behaviour.lower()} gesture needs a target (x, y, z) in the character frame.")
    if kind == "intensity" and (spec.exaggeration is None or not 0.0 <= float(spec.exaggeration) <= 1.0):
        raise RLAnimateError(f"A {spec.behaviour.lower()} gesture needs an exaggeration between 0 and 1.")
    return synthesiser(spec, draw_style(spec.seed))
