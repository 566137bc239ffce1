"""Procedural pointing, waving, guiding ("this way") and hand-raising clips on the canonical rig, in plain numpy.

A gesture spec (behaviour, arm, target or exaggeration, style seed) becomes per-frame local rotation
vectors, at 30 fps, for the 15 action joints and the finger bones. The motion is built the way an
animator blocks it: key poses (neutral, the pointing hold or the raised wave), solved in world space
with analytic two-bone IK, then timed per body part with minimum-jerk segments:

    time ->  lead-in | anticipation | stroke        | settle | hold ...... | return       | settle | rest
    gaze     .........=======>                                   ====>
    torso    ..............=============>                          =========>
    arm      ...........<-- ======================> ~~~>             ==============> ~~>
    hand     ......................===================>                ==============>

Gaze (neck, head; the eyes ride on the head) leads, the torso follows, the arm winds up slightly,
strokes with a bell-shaped speed profile, overshoots a little and settles; the hand and fingers
arrive last. Every clip starts and ends in the same relaxed neutral pose (`neutral_pose`).

Pointing contract: at the hold the index-finger base lies on the ray from the arm's rest shoulder
joint along `spaces.pointing_direction(arm, target)`, and the finger (Index1 head -> Index4 head)
runs along that ray, so its line passes through the target at any distance.
"""
from .arms import neutral_pose
from .clips import GUIDE, MAX_WAVING, POINT, RAISE_HAND, SYNTHESISERS, WAVE, GestureClip, synthesise
from .pose import ANIMATED_BONES, FINGER_BONES, FPS
from .style import GestureSpec, Style, draw_style
from .timing import keyed_progress

__all__ = [
    "ANIMATED_BONES",
    "FINGER_BONES",
    "FPS",
    "GUIDE",
    "MAX_WAVING",
    "POINT",
    "RAISE_HAND",
    "SYNTHESISERS",
    "WAVE",
    "GestureClip",
    "GestureSpec",
    "Style",
    "draw_style",
    "keyed_progress",
    "neutral_pose",
    "synthesise",
]
