"""Reads a wave clip's rhythm (core/rhythm.py) from its motion: the hand's side-to-side swing.

The swing signal is the waving wrist's outward offset from its shoulder, in the character frame
(forward kinematics of the canonical skeleton, core/kinematics.py). Subtracting a cubic Savitzky-Golay fit over half a second removes the raise and the lowering;
its analytic signal (Hilbert transform) gives the swing's phase and amplitude per frame. The
envelope's half-amplitude frames and a line through the unwrapped phase give the Rhythm.
"""
import numpy as np
from scipy import signal

from rlanimate_addon.core import kinematics, rhythm, skeleton
from rlanimate_addon.core.errors import RLAnimateError

#: Window (s) of the cubic Savitzky-Golay fit that takes out the raise and the lowering: it follows
#: a half-second raise but not a 2-3 Hz swing.
SMOOTHING_SECONDS = 0.5
#: Metres: a swing whose amplitude never reaches this is no swing.
MIN_SWING = 0.01
#: Seconds over which the swing envelope rises and falls.
RAMP_SECONDS = 0.3
_OUTWARD = {"LEFT": 1.0, "RIGHT": -1.0}  # +X is the character's left


def swing_signal(rotvecs, arm):
    """(F,) outward offset (metres) of the waving wrist from its shoulder, from the clip's action
    rotations (F, 15, 3)."""
    side = skeleton.ARM_PREFIX[arm]
    pose = kinematics.pose_matrices(dict(zip(skeleton.ACTION_JOINTS, np.moveaxis(rotvecs, 1, 0))),
                                    only=[side + "Hand"])
    heads = kinematics.head_positions(pose)  # (F, B, 3)
    wrist, shoulder = kinematics.bone_index(side + "Hand"), kinematics.bone_index(side + "Arm")
    return _OUTWARD[arm] * (heads[:, wrist, 0] - heads[:, shoulder, 0])


def clip_rhythm(clip):
    """The Rhythm of a wave clip (a MotionClip with rotvecs, arm and fps), or None for a wave whose hand
    does not swing side to side (real takes have them: a raised, still hand)."""
    fps = clip.fps
    x = swing_signal(np.asarray(clip.rotvecs, dtype=np.float64), clip.arm.upper())
    frames = len(x)
    window = 2 * int(round(SMOOTHING_SECONDS * fps / 2)) + 1
    if frames <= 2 * window:
        raise RLAnimateError(f"A wave clip of {frames} frames is too short to read its swing: use longer clips.")
    analytic = signal.hilbert(x - signal.savgol_filter(x, window, 3))
    amplitude = np.abs(analytic)
    if amplitude.max() < MIN_SWING:
        return None
    above = amplitude >= 0.5 * amplitude.max()
    peak = int(np.argmax(amplitude))  # the swing: the run of frames above half amplitude around the peak
    first = peak - np.argmin(above[peak::-1]) + 1 if not above[:peak + 1].all() else 0
    last = peak + np.argmin(above[peak:]) - 1 if not above[peak:].all() else frames - 1
    active = np.arange(first, last + 1)
    if len(active) < 4:
        return None
    ramp = RAMP_SECONDS * fps
    start, stop = active[0] - 0.5 * ramp, active[-1] + 0.5 * ramp
    phase = np.unwrap(np.angle(analytic))
    slope = np.polyfit(active, phase[active], 1)[0]
    offset = np.angle(np.mean(amplitude[active] * np.exp(1j * (phase[active] - slope * (active - start)))))
    span = frames - 1
    return rhythm.Rhythm(frequency=float(slope / (2.0 * np.pi)), start=float(start / span),
                         stop=float(stop / span), phase=float(offset), ramp=float(ramp))
