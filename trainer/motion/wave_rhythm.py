"""Reads a wave clip's rhythm (core/rhythm.py) from its motion: the hand's side-to-side swing.

The swing signal is the waving wrist's outward offset from its shoulder, in the character frame
(forward kinematics of the canonical skeleton, core/kinematics.py). Its rate is the peak of the
signal's spectrum over the frames where the arm is raised (autolabel.raised_frames), between
WAVE_BAND; a zero-phase Butterworth band-pass around that rate removes the raise, the lowering and
the stroke's harmonics, and its analytic signal (Hilbert transform) gives the swing's phase and
amplitude per frame. The raised frames where the amplitude is at least half its peak give when the
swing starts and stops, and a line through the unwrapped phase over them its rate.

A fixed high-pass would not do: real waves swing at 0.8-3 Hz, and a filter that takes out a
half-second raise also takes out a 1 Hz swing, leaving its harmonics (docs/REALMOCAP.md).
"""
import numpy as np
from scipy import signal

from rlanimate_addon.core import kinematics, rhythm, skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion import autolabel

#: Hz: the rates a hand wave swings at (real takes 0.8-3 Hz, the sample library 2-2.7 Hz).
WAVE_BAND = (0.5, 5.0)
#: The band-pass keeps rates within this factor of the swing's own.
BAND_WIDTH = 1.4
BAND_ORDER = 4
#: Metres: a swing whose amplitude never reaches this is no swing.
MIN_SWING = 0.01
#: Seconds over which the swing envelope rises and falls.
RAMP_SECONDS = 0.3
#: Seconds: the shortest wave clip whose swing can be read.
MIN_SECONDS = 1.0
_OUTWARD = {"LEFT": 1.0, "RIGHT": -1.0}  # +X is the character's left


def swing_signal(rotvecs, arm):
    """(F,) outward offset (metres) of the waving wrist from its shoulder, from the clip's action
    rotations (F, 15, 3)."""
    side = skeleton.ARM_PREFIX[arm]
    pose = kinematics.pose_matrices(dict(zip(skeleton.ACTION_JOINTS, np.moveaxis(rotvecs, 1, 0), strict=True)),
                                    only=[side + "Hand"])
    heads = kinematics.head_positions(pose)  # (F, B, 3)
    wrist, shoulder = kinematics.bone_index(side + "Hand"), kinematics.bone_index(side + "Arm")
    return _OUTWARD[arm] * (heads[:, wrist, 0] - heads[:, shoulder, 0])


def swing_rate(x, fps):
    """Hz: the peak of the periodogram of (F,) `x`, less its trend, within WAVE_BAND."""
    frequencies, power = signal.periodogram(signal.detrend(x), fs=fps, window="hann", nfft=max(4096, len(x)))
    inside = (frequencies >= WAVE_BAND[0]) & (frequencies <= WAVE_BAND[1])
    return float(frequencies[inside][np.argmax(power[inside])])


def clip_rhythm(clip):
    """The Rhythm of a wave clip (a MotionClip with rotvecs, arm and fps), or None for a wave whose hand
    does not swing side to side (real takes have them: a raised, still hand)."""
    fps = clip.fps
    rotvecs = np.asarray(clip.rotvecs, dtype=np.float64)
    arm = clip.arm.upper()
    x = swing_signal(rotvecs, arm)
    frames = len(x)
    if frames < MIN_SECONDS * fps:
        raise RLAnimateError(f"A wave clip of {frames} frames is too short to read its swing: use clips of at "
                             f"least {MIN_SECONDS:g} s.")
    raised = np.flatnonzero(autolabel.raised_frames(rotvecs, arm))
    up = np.arange(raised[0], raised[-1] + 1)
    rate = swing_rate(x[up], fps)
    band = (rate / BAND_WIDTH, min(rate * BAND_WIDTH, 0.45 * fps))
    sections = signal.butter(BAND_ORDER, band, btype="band", fs=fps, output="sos")
    padding = min(frames - 1, 3 * (2 * len(sections) + 1))  # scipy's own, or what a short clip allows
    analytic = signal.hilbert(signal.sosfiltfilt(sections, x, padlen=padding))
    amplitude = np.abs(analytic)
    peak = amplitude[up].max()
    if peak < MIN_SWING:
        return None
    swinging = up[amplitude[up] >= 0.5 * peak]
    active = np.arange(swinging[0], swinging[-1] + 1)
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


def clip_signals(clip, frame_count):
    """(frame_count, 2) rhythm signals (core.rhythm.signals) of a wave clip's own rhythm (clip_rhythm): what the
    task module knows in training; zeros, no swing, for a wave whose hand does not swing."""
    read = clip_rhythm(clip)
    return np.zeros((frame_count, 2)) if read is None else rhythm.signals(read, frame_count)


def clip_tempo(clip):
    """Hz: how fast a wave clip's hand swings side to side (clip_rhythm), the tempo a request for it names;
    None for a wave whose hand does not swing."""
    read = clip_rhythm(clip)
    return None if read is None else read.frequency * clip.fps


def tempo_reading(clip):
    """(Hz, None): the tempo a request for a wave clip names (clip_tempo), or (None, why not) for a take whose tempo
    cannot be read: one shorter than MIN_SECONDS, or one whose hand does not swing side to side. A request for such
    a take names no tempo: its rhythm comes from its label."""
    if too_short(clip):
        return None, f"{clip.frames} frames, under {MIN_SECONDS:g} s: too short to read its swing"
    tempo = clip_tempo(clip)
    return (tempo, None) if tempo is not None else (None, "its hand does not swing side to side")


def too_short(clip):
    """Whether a wave clip is shorter than MIN_SECONDS, too short to read its swing."""
    return clip.frames < MIN_SECONDS * clip.fps


def swinging(waves):
    """[(clip, its Rhythm)] of the wave clips whose hand swings side to side (clip_rhythm), in their order."""
    return [(clip, read) for clip in waves if (read := clip_rhythm(clip)) is not None]


def fit_rhythm_model(waves):
    """The RhythmModel of wave clips, fitted on those whose hand swings (`swinging`)."""
    return rhythm_model(swinging(waves))


def rhythm_model(read):
    """The RhythmModel of `swinging`'s (clip, Rhythm) pairs, by the clips' exaggeration (`.attributes`) and arm."""
    return rhythm.RhythmModel.fit([clip.attributes for clip, _ in read], [r for _, r in read],
                                  [clip.arm for clip, _ in read])
