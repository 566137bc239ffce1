"""The baselines an animator would try before RLAnimate, producing clips the evaluator scores.

Each answers the agent's request (behaviour, arm, label attributes, frame count, and for a wave
optionally its tempo in Hz) with a clip of local rotations (F, 15, 3) of skeleton.ACTION_JOINTS, like
MotionClip.rotvecs:

NoMotion         the start pose held: a still arm (tempo ignored).
ClassMean        the per-frame mean of the training clips of the same behaviour and arm, label and
                 tempo ignored.
NearestClip      retrieval, as motion matching does: the training clip of the same behaviour and arm
                 whose label is closest (angle between pointing directions; |difference| of
                 exaggerations; with a tempo, the distance in exaggeration and log tempo, each in units
                 of its sd over the candidates), time-warped uniformly to the requested length
                 (per-joint slerp).
ProceduralIK     Blender's IK constraint on the sample rig (trainer/blender_io/procedural_ik.py), swinging
                 at the tempo.

Nearest clip and procedural IK start from and return to `mean_start_pose(clips)` (15, 3), the pose
the training clips start in.
AgentMethod (an exported .npz, numpy runtime: what the add-on plays) puts RLAnimate behind the same
generate() interface, so all are scored by one code path.
"""
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from rlanimate_addon.core import behaviours, rotations, spaces
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.gesture import slerp
from trainer.motion.clip import MotionClip
from trainer.motion.wave_rhythm import tempo_reading


def mean_start_pose(clips: Sequence[MotionClip]) -> np.ndarray:
    """(15, 3) start pose: the mean first frame of `clips` (they all start standing neutrally)."""
    if not clips:
        raise RLAnimateError("No training clips: a baseline needs at least one clip to start from.")
    quats = rotations.rotvec_to_quat(np.stack([np.asarray(c.rotvecs[0]) for c in clips]))  # (C, 15, 4)
    return rotations.quat_to_rotvec(rotations.quat_mean(quats))


def time_warp(rotvecs: ArrayLike, frame_count: int) -> np.ndarray:
    """(M, 15, 3) -> (frame_count, 15, 3), uniform time scaling with per-joint slerp, ends kept."""
    quats = rotations.rotvec_to_quat(np.asarray(rotvecs, dtype=np.float64))  # (M, 15, 4)
    position = np.linspace(0.0, len(quats) - 1, int(frame_count))
    low = np.floor(position).astype(int)
    high = np.minimum(low + 1, len(quats) - 1)
    weight = np.broadcast_to((position - low)[:, None], (len(position), quats.shape[1]))
    return rotations.quat_to_rotvec(slerp(quats[low], quats[high], weight))


def clips_of(clips: Sequence[MotionClip], behaviour: str, arm: str, baseline: str) -> list[MotionClip]:
    """The clips of `behaviour` and `arm`; RLAnimateError naming the `baseline` that needs one when there are none."""
    group = [c for c in clips if c.behaviour == behaviour and c.arm == arm]
    if not group:
        raise RLAnimateError(f"No {behaviours.key(behaviour)} training clip uses the {arm.lower()} arm: "
                             f"add one to the library to use the {baseline} baseline.")
    return group


class NearestClip:
    """Motion-matching retrieval over labelled training clips (MotionClip-like: behaviour, arm,
    attributes, rotvecs)."""

    def __init__(self, clips):
        self.clips = list(clips)
        self._tempos = {}  # {id(clip): its tempo (Hz) or None (tempo_reading)}, read when a request first names one

    def nearest(self, behaviour, arm, attributes, tempo=None, exclude=None):
        """The training clip of `behaviour` and `arm` whose label (and tempo, Hz, when given) is closest to
        the request's; never the clip `exclude` (leave-one-out: the take a request was read from)."""
        candidates = clips_of([c for c in self.clips if c is not exclude], behaviour, arm, "nearest-clip")
        kind = candidates[0].behaviour_kind
        if tempo is not None:
            return self._nearest_in_tempo(candidates, float(np.ravel(attributes)[0]), float(tempo))
        return min(candidates, key=lambda c: self.label_distance(kind, c.attributes, attributes))

    def _nearest_in_tempo(self, candidates, exaggeration, tempo):
        """The candidate nearest (exaggeration, log tempo), each in units of its sd over the candidates
        whose tempo can be read; one whose tempo cannot only when none can."""
        for clip in candidates:
            if id(clip) not in self._tempos:
                self._tempos[id(clip)] = tempo_reading(clip)[0]
        tempos = [self._tempos[id(c)] for c in candidates]
        swinging = [(c, t) for c, t in zip(candidates, tempos, strict=True) if t is not None]
        if not swinging:
            return min(candidates, key=lambda c: abs(float(np.ravel(c.attributes)[0]) - exaggeration))
        values = np.array([[float(np.ravel(c.attributes)[0]), np.log(t)] for c, t in swinging])  # (K, 2)
        scale = np.maximum(values.std(axis=0), 1e-6)
        distances = np.linalg.norm((values - [exaggeration, np.log(tempo)]) / scale, axis=1)
        return swinging[int(np.argmin(distances))][0]

    @staticmethod
    def label_distance(kind, a, b):
        """Angle (rad) between the directions of a target behaviour, or |difference| of exaggerations."""
        if kind == behaviours.TARGET:
            a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
            cos = a @ b / (np.linalg.norm(a) * np.linalg.norm(b))
            return float(np.arccos(np.clip(cos, -1.0, 1.0)))
        return abs(float(np.ravel(a)[0]) - float(np.ravel(b)[0]))

    def generate(self, behaviour, arm, attributes, frame_count, tempo=None, exclude=None):
        spaces.check_arm_and_length(arm, frame_count)
        return time_warp(self.nearest(behaviour, arm, attributes, tempo, exclude).rotvecs, frame_count)


class NoMotion:
    """The start pose held for the whole request: what a still arm scores."""

    def __init__(self, neutral):
        self.neutral = np.asarray(neutral, dtype=np.float64)  # (15, 3)

    def generate(self, behaviour, arm, attributes, frame_count, tempo=None):
        spaces.check_arm_and_length(arm, frame_count)
        return np.repeat(self.neutral[None], int(frame_count), axis=0)


class ClassMean:
    """The per-frame mean of the training clips of the request's behaviour and arm, each time-warped
    to the requested length (per-joint normalised quaternion mean): it ignores the label, and the mean
    of waves whose phases differ is a nearly still raised arm."""

    def __init__(self, clips):
        self.clips = list(clips)

    def generate(self, behaviour, arm, attributes, frame_count, tempo=None):
        spaces.check_arm_and_length(arm, frame_count)
        group = clips_of(self.clips, behaviour, arm, "class-mean")
        quats = rotations.rotvec_to_quat(np.stack([time_warp(c.rotvecs, frame_count) for c in group]))  # (C, F, 15, 4)
        return rotations.quat_to_rotvec(rotations.quat_mean(quats))


class AgentMethod:
    """An exported RLAnimate agent (.npz) behind the baselines' generate() interface: the deterministic
    numpy rollout on the request's objectives, decoded to rotations."""

    def __init__(self, path):
        from rlanimate_addon.core import runtime
        self.path = Path(path)
        self.agent = runtime.load_agent(self.path)

    def generate(self, behaviour, arm, attributes, frame_count, seed=None, tempo=None):
        """Deterministic without `seed`; with one, the runtime's seeded sampling (as the panel's seed), and for
        a wave the rhythm the agent draws for the seed."""
        return agent_motion(self.agent, behaviour, arm, attributes, frame_count, seed, seed, tempo)


def agent_motion(agent, behaviour, arm, attributes, frame_count, rhythm_seed=None, state_seed=None, tempo=None,
                 rhythm_signals=None):
    """(F, 15, 3) rotations the runtime agent (core.runtime.GestureAgent) plays for the request: a wave's
    rhythm drawn with `rhythm_seed` (RhythmModel.draw) at `tempo` (Hz; None: the agent's), or the
    `rhythm_signals` given ((F, 2), core.rhythm.signals), the stochastic states sampled with `state_seed`
    (None: their means). A tempo beyond what the agent learned is played at the nearest it allows, as an
    animator would set it when the panel refuses theirs (real goodbye waves reach 4.5 Hz)."""
    if tempo is not None and agent.tempo_range() is not None:
        tempo = float(np.clip(tempo, *agent.tempo_range()))
    signals = rhythm_signals
    if signals is None and agent.space.behaviour(behaviour).oscillates:
        signals = agent.wave_rhythm(attributes, frame_count, rhythm_seed, tempo, arm)
    objectives = agent.space.make_objective(behaviour, arm, attributes, frame_count, signals)
    return spaces.decode_action(agent.rollout(objectives, seed=state_seed), np.asarray(agent.action_bounds))


def generate_for(baseline: Any, clips: Sequence[MotionClip], with_tempo: bool = False) -> list[np.ndarray]:
    """The baseline's answer to each clip's own request (label and length, and `with_tempo` a wave's own
    tempo where it can be read, request_tempos): list of (F_i, 15, 3)."""
    return generate_at(baseline, clips, request_tempos(clips, with_tempo)[0])


def generate_at(baseline: Any, clips: Sequence[MotionClip], tempos: Sequence[float | None]) -> list[np.ndarray]:
    """The baseline's answer to each clip's request (label and length) naming the tempo of `tempos` (Hz, or None)
    beside it: list of (F_i, 15, 3)."""
    return [baseline.generate(c.behaviour, c.arm, c.attributes, len(c.rotvecs), tempo=tempo)
            for c, tempo in zip(clips, tempos, strict=True)]


def request_tempos(clips: Sequence[MotionClip], with_tempo: bool) -> tuple[list[float | None], dict[str, str]]:
    """(tempos, fallbacks): the tempo (Hz) each clip's request names, and {clip name: why} for the waves whose
    request falls back to the label when `with_tempo` (a take under a second, one that does not swing)."""
    readings = [request_tempo_reading(clip, with_tempo) for clip in clips]
    return [tempo for tempo, _ in readings], {c.name: why for c, (_, why) in zip(clips, readings, strict=True) if why}


def request_tempo(clip: MotionClip, with_tempo: bool) -> float | None:
    """The tempo (Hz) a request for `clip` names: the wave's own when `with_tempo` and it can be read, else None."""
    return request_tempo_reading(clip, with_tempo)[0]


def request_tempo_reading(clip: MotionClip, with_tempo: bool) -> tuple[float | None, str | None]:
    """(tempo in Hz or None, why a wave's request asked for a tempo names none, else None)."""
    if not with_tempo or not clip.declared.oscillates:
        return None, None
    return tempo_reading(clip)
