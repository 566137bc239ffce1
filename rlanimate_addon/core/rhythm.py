"""The wave's rhythm as part of the objective: when the hand swings, and at what phase.

The paper's wave objective carries only the exaggeration (three times). Clips of the same
exaggeration swing at different phases, rates and counts, and nothing in that objective tells them
apart, so the per-frame regression of the animation model onto them averages out-of-phase swings
into a still arm. Here the wave's attributes are [exaggeration, A_t sin(phi_t), A_t cos(phi_t)]:

    phi_t = phase + 2 pi frequency (t - start)          frequency in cycles per frame
    A_t   = smoothstep((t - start) / ramp) * smoothstep((stop - t) / ramp)

with start and stop in frames (given as fractions of the gesture, so a longer gesture swings for
proportionally longer). During training the task module reads these from each clip
(trainer/motion/wave_rhythm.py); at play time `RhythmModel.draw` takes them from the training waves near
the request: near its exaggeration, and near its tempo in log Hz. The tempo is the one the request names
(the panel's Tempo), or else the typical tempo of the waves near its exaggeration: the mode of their
tempos, not their mean. Styles of one exaggeration can swing at different rates (real masculine and
normal waves: 0.67 ± 0.06 and 0.62 ± 0.10, at 0.85 and 1.6 Hz; docs/REALMOCAP.md), and the mean of two
rates is a rate neither style swings at, as the mean of out-of-phase swings is a still arm. Seed None
plays those waves' weighted mean rate, start and stop at their weighted circular mean phase; a seed plays
one of them (by weight) at any phase, so seeds vary the phase, rate and number of swings within what
those waves do. A named tempo sets the rate.
Files exported before the training waves' phases were kept (`phases` None) play as they were made: the
rate, start and stop near the exaggeration alone at the circular mean phase of all the training waves
(`typical_tempo` False; docs/results/realmocap_ablation.md compares the two). The kernels, and whether a
request weighs only the training waves of its own arm (`by_arm`, as retrieval fetches only that arm's), are
chosen on real-capture validation takes (docs/results/realmocap_length.md) and kept in the file.
"""
import json
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from .errors import RLAnimateError
from .skeleton import ARMS

#: The parameters of a rhythm that a request takes from the training waves of nearby exaggeration.
PARAMETERS = ("frequency", "start", "stop")
#: A requested tempo may lie this factor beyond the slowest and fastest training waves' (tempo_range).
TEMPO_MARGIN = 1.25
#: Exaggeration: the training waves within about this of a request's weigh in its rhythm (a Gaussian
#: kernel's sd; each file keeps its own). Styles of one exaggeration can swing at different rates
#: (docs/REALMOCAP.md), so the rhythm is a local average, not a line through all the waves.
BANDWIDTH = 0.15
#: Log Hz: the training waves within about this of a request's tempo (asked or typical) weigh in its rhythm
#: (a Gaussian kernel's sd; a file may keep its own, `tempo_bandwidth`): a narrow one, so that the rate
#: played is the typical tempo's, not pulled towards another style's.
TEMPO_BANDWIDTH = math.log(1.05)
#: Whether a request weighs only the training waves of its own arm (when the file keeps the arms).
BY_ARM = False
# The three above were chosen together on real-capture validation takes, over three seeds (sd 0.05-0.15, log
# 1.05-1.25, own arm or both; docs/results/realmocap_length.md); files made before keep theirs (0.05, log 1.25).
#: Log Hz: the tempo kernel of the files made before they kept theirs, which they play.
EARLIER_TEMPO_BANDWIDTH = math.log(1.25)


@dataclass(frozen=True)
class Rhythm:
    frequency: float  # cycles per frame
    start: float  # the swing envelope starts rising, as a fraction of the gesture (t / (N - 1))
    stop: float  # ... and has fallen back to zero
    phase: float  # radians, at `start`
    ramp: float  # frames over which the envelope rises and falls

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def signals(rhythm: "Rhythm", frame_count: int) -> npt.NDArray[np.float64]:
    """(N, 2) [A_t sin(phi_t), A_t cos(phi_t)] of `rhythm` over a gesture of `frame_count` frames."""
    t = np.arange(int(frame_count), dtype=np.float64)
    span = max(int(frame_count) - 1, 1)
    start, stop = rhythm.start * span, rhythm.stop * span
    envelope = _smoothstep((t - start) / rhythm.ramp) * _smoothstep((stop - t) / rhythm.ramp)
    phi = rhythm.phase + 2.0 * np.pi * rhythm.frequency * (t - start)
    return np.stack([envelope * np.sin(phi), envelope * np.cos(phi)], axis=1)


def _smoothstep(x: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    s = np.clip(x, 0.0, 1.0)
    return s * s * (3.0 - 2.0 * s)


class RhythmModel:
    """The training clips' rhythms as an agent file stores them (`to_dict` / `from_dict`).

    `examples` (K, 4): each training wave's exaggeration and its PARAMETERS; the phase's circular mean;
    the envelope ramp in frames; the kernel bandwidth in exaggeration; `phases` (K,): each training
    wave's phase (None in files exported before they were kept); `typical_tempo`: the waves near the
    request's tempo weigh in its rhythm, and theirs is its phase (it needs `phases`; None: on when they
    are there); `tempo_bandwidth`: that tempo kernel's sd in log Hz; `arms` (K,): each training wave's arm
    ("LEFT" or "RIGHT"; None in files exported before they were kept); `by_arm`: a request weighs only its
    own arm's waves (it needs `arms`).
    """

    def __init__(self, examples: ArrayLike, phase: float, ramp: float, bandwidth: float = BANDWIDTH,
                 phases: ArrayLike | None = None, typical_tempo: bool | None = None,
                 tempo_bandwidth: float = TEMPO_BANDWIDTH, arms: Sequence[str] | None = None,
                 by_arm: bool = BY_ARM) -> None:
        self.examples = np.asarray(examples, dtype=np.float64)
        self.phase, self.ramp, self.bandwidth = float(phase), float(ramp), float(bandwidth)
        self.phases = None if phases is None else np.asarray(phases, dtype=np.float64)
        self.typical_tempo = self.phases is not None if typical_tempo is None else typical_tempo
        self.tempo_bandwidth = float(tempo_bandwidth)
        self.arms = None if arms is None else tuple(arms)
        self.by_arm = by_arm

    @classmethod
    def fit(cls, exaggerations: Sequence[float], rhythms: Sequence[Rhythm],
            arms: Sequence[str] | None = None) -> "RhythmModel":
        """From the training clips' exaggerations (K,), their Rhythms (K) and arms (K; None: not known)."""
        if len(exaggerations) < 2:
            raise RLAnimateError("Fitting the wave rhythm needs at least 2 wave clips whose hand swings side to "
                                 "side: add such wave clips.")
        examples = [
            [float(e)] + [getattr(r, name) for name in PARAMETERS] for e, r in zip(exaggerations, rhythms, strict=True)
        ]
        phases = np.array([r.phase for r in rhythms])
        phase = float(np.angle(np.mean(np.exp(1j * phases))))
        return cls(examples, phase, float(np.mean([r.ramp for r in rhythms])), phases=phases, arms=arms)

    def with_settings(self, bandwidth: float | None = None, typical_tempo: bool | None = None,
                      tempo_bandwidth: float | None = None, by_arm: bool | None = None) -> "RhythmModel":
        """The same training waves with another kernel bandwidth, choice of `typical_tempo`, tempo kernel and/or
        `by_arm` (None: keep this one's)."""
        return RhythmModel(self.examples, self.phase, self.ramp, self.bandwidth if bandwidth is None else bandwidth,
                           self.phases, self.typical_tempo if typical_tempo is None else typical_tempo,
                           self.tempo_bandwidth if tempo_bandwidth is None else tempo_bandwidth, self.arms,
                           self.by_arm if by_arm is None else by_arm)

    def to_dict(self) -> dict[str, Any]:
        values: dict[str, Any] = {"examples": self.examples.tolist(), "phase": self.phase, "ramp": self.ramp,
                  "bandwidth": self.bandwidth}
        if self.phases is not None:
            values.update(phases=self.phases.tolist(), typical_tempo=self.typical_tempo,
                          tempo_bandwidth=self.tempo_bandwidth)
        if self.arms is not None:
            values.update(arms=list(self.arms), by_arm=self.by_arm)
        return values

    @classmethod
    def from_dict(cls, values: dict[str, Any]) -> "RhythmModel":
        """The model an agent file's `wave_rhythm` holds; RLAnimateError naming the field that is wrong
        (`invalid_field`)."""
        problem = invalid_field(values)
        if problem:
            raise RLAnimateError(f"The agent's wave_rhythm metadata is invalid ({problem}): re-export the agent "
                                 f"with trainer/agent/agent_export.py.")
        return cls(values["examples"], values["phase"], values["ramp"], values["bandwidth"], values.get("phases"),
                   values.get("typical_tempo"), values.get("tempo_bandwidth", EARLIER_TEMPO_BANDWIDTH),
                   values.get("arms"), bool(values.get("by_arm")))

    def weights(self, exaggeration: float, tempo: float | None = None,
                arm: str | None = None) -> npt.NDArray[np.float64]:
        """(K,) how much each training wave weighs in a request of this exaggeration (sum 1): with `by_arm`, only
        those of its `arm` where there are any (None: both arms'); with `typical_tempo`, near its tempo too
        (cycles per frame; None: the typical one)."""
        log_kernel = _log_gaussian(self.examples[:, 0] - float(exaggeration), self.bandwidth)  # (K,)
        if self.by_arm and self.arms is not None and arm in self.arms:
            log_kernel = np.where(np.array(self.arms) == arm, log_kernel, -np.inf)
        if not self.typical_tempo:
            return _normalised(log_kernel)
        frequencies = self._frequencies()
        log_tempos = np.log(frequencies)  # (K,)
        if tempo is None:
            nearby = np.exp(_log_gaussian(log_tempos[:, None] - log_tempos[None, :], self.tempo_bandwidth))  # (K, K)
            tempo = frequencies[np.argmax(nearby @ _normalised(log_kernel))]  # the densest tempo
        return _normalised(log_kernel + _log_gaussian(log_tempos - math.log(max(float(tempo), _SLOWEST)),
                                                      self.tempo_bandwidth))

    def _frequencies(self) -> npt.NDArray[np.float64]:
        return np.maximum(self.examples[:, 1 + PARAMETERS.index("frequency")], _SLOWEST)

    def tempo_range(self) -> tuple[float, float]:
        """(slowest, fastest) tempo a request may ask, in cycles per frame: the training waves' own,
        widened by TEMPO_MARGIN."""
        frequencies = self.examples[:, 1 + PARAMETERS.index("frequency")]
        return float(frequencies.min() / TEMPO_MARGIN), float(frequencies.max() * TEMPO_MARGIN)

    def draw(self, exaggeration: float, seed: int | None = None, tempo: float | None = None,
             arm: str | None = None) -> Rhythm:
        """The Rhythm for a wave of this exaggeration by `arm`: for seed None the weighted mean of the training
        waves' rhythms (`weights`), else a seeded draw of one training wave's (by weight) at any phase; at
        `tempo` (cycles per frame; the caller keeps it within tempo_range) when given."""
        weights = self.weights(exaggeration, tempo, arm)
        if seed is None:
            values = weights @ self.examples[:, 1:]
            phase = self.phase
            if self.typical_tempo:
                assert self.phases is not None, "typical_tempo needs the phases (invalid_field)"
                phase = float(np.angle(weights @ np.exp(1j * self.phases)))
        else:
            rng = np.random.default_rng(seed)
            values, phase = self.examples[rng.choice(len(weights), p=weights), 1:], float(rng.uniform(-np.pi, np.pi))
        frequency, start, stop = (float(v) for v in values)
        frequency = frequency if tempo is None else float(tempo)
        start = float(np.clip(start, 0.0, 1.0))
        return Rhythm(max(frequency, 0.0), start, float(np.clip(stop, start, 1.0)), phase, self.ramp)


#: How many phase features a phase-input agent's heads see beside its task state (`phase_features`).
PHASE_FEATURES = 4


def phase_features(signals: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(..., 4) [A sin(phi), A cos(phi), A sin(2 phi), A cos(2 phi)] of rhythm signals (..., 2) [A sin(phi),
    A cos(phi)]: the swing's phase and its second harmonic, as phase-conditioned motion models give the pose
    network its phase (an agent with AgentConfig.phase_input; the trainer's torch model computes the same)."""
    sine, cosine = signals[..., 0], signals[..., 1]
    amplitude = np.maximum(np.hypot(sine, cosine), 1e-9)
    return np.stack([sine, cosine, 2.0 * sine * cosine / amplitude, (cosine ** 2 - sine ** 2) / amplitude], axis=-1)


#: Below this product of two frames' swing amplitudes the hand does not swing between them (`swing_rate`).
STILL_PRODUCT = 1e-24


def swing_rate(signals: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(..., T, 1) the swing's phase advance per frame (radians: 2 pi x the tempo in cycles a frame) of rhythm signals
    (..., T, 2), read from each frame and the next (from the one before at the last frame, or where the next is
    still), 0 where the hand does not swing: the tempo an agent with AgentConfig.tempo_input sees beside the phase
    (the trainer's torch model computes the same)."""
    sine, cosine = signals[..., 0], signals[..., 1]
    real = cosine[..., 1:] * cosine[..., :-1] + sine[..., 1:] * sine[..., :-1]  # (..., T - 1): z_{t+1} conj(z_t)
    imaginary = sine[..., 1:] * cosine[..., :-1] - cosine[..., 1:] * sine[..., :-1]
    swinging = real ** 2 + imaginary ** 2 > STILL_PRODUCT
    advance = np.where(swinging, np.arctan2(imaginary, real), 0.0)
    none, still = np.zeros(advance.shape[:-1] + (1,)), np.zeros(swinging.shape[:-1] + (1,), bool)
    ahead, ahead_swings = np.concatenate([advance, none], -1), np.concatenate([swinging, still], -1)
    behind, behind_swings = np.concatenate([none, advance], -1), np.concatenate([still, swinging], -1)
    rate: npt.NDArray[np.float64] = np.where(ahead_swings, ahead, np.where(behind_swings, behind, 0.0))
    return rate[..., None]


#: Cycles per frame: the slowest rate a tempo's logarithm is taken of.
_SLOWEST = 1e-6


def _log_gaussian(differences: npt.NDArray[np.float64], bandwidth: float) -> npt.NDArray[np.float64]:
    log_kernel: npt.NDArray[np.float64] = -0.5 * (differences / bandwidth) ** 2
    return log_kernel


def _normalised(log_weights: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Weights (sum 1) from their logarithms, shifted so that far ones still have weights."""
    weights = np.exp(log_weights - log_weights.max())
    normalised: npt.NDArray[np.float64] = weights / weights.sum()
    return normalised


#: The numbers of a rhythm model, each: JSON numbers within this (1e300 squared is infinite).
_LARGEST = 1e300


def _finite(value: object) -> bool:
    """A JSON number (not a boolean) that is finite and within +-_LARGEST."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return abs(value) <= _LARGEST if isinstance(value, int) else math.isfinite(value) and abs(value) <= _LARGEST


def _json_type(value: object) -> str:
    """How a message names a JSON value's type."""
    names = {bool: "a boolean", str: "a string", list: "a list", dict: "an object", type(None): "null"}
    return names.get(type(value), "a number")


def invalid_field(values: object) -> str | None:
    """What is wrong with an agent file's `wave_rhythm` value, naming the field (None: nothing). Every field
    RhythmModel reads is checked for its JSON type, its length (one per training wave) and its range."""
    if not isinstance(values, dict):
        return f"wave_rhythm is {_json_type(values)}, not an object holding the training waves' rhythms"
    missing = [key for key in ("examples", "phase", "ramp", "bandwidth") if key not in values]
    if missing:
        return f"wave_rhythm lacks {', '.join(missing)}"
    examples, width = values["examples"], 1 + len(PARAMETERS)
    if not isinstance(examples, list) or len(examples) < 2 or not all(
            isinstance(row, list) and len(row) == width and all(_finite(v) for v in row) for row in examples):
        return f"wave_rhythm.examples must be a list of at least 2 lists of {width} finite numbers"
    count = len(examples)
    if not _finite(values["phase"]):
        return "wave_rhythm.phase must be a finite number"
    for key in ("ramp", "bandwidth", "tempo_bandwidth"):
        if key in values and not (_finite(values[key]) and values[key] > 0):
            return f"wave_rhythm.{key} must be a positive number, not {json.dumps(values[key])[:40]}"
    phases, arms = values.get("phases"), values.get("arms")
    if phases is not None and not (isinstance(phases, list) and len(phases) == count and all(map(_finite, phases))):
        return f"wave_rhythm.phases must be null or a list of {count} finite numbers, one per training wave"
    if arms is not None and not (isinstance(arms, list) and len(arms) == count
                                 and all(isinstance(a, str) and a in ARMS for a in arms)):
        return f"wave_rhythm.arms must be null or a list of {count} arms, each {' or '.join(map(repr, ARMS))}"
    for key, needs, needed in (("typical_tempo", "phases", phases), ("by_arm", "arms", arms)):
        flag = values.get(key)
        if flag is not None and not isinstance(flag, bool):
            return f"wave_rhythm.{key} must be true or false, not {_json_type(flag)}"
        if flag and needed is None:
            return f"wave_rhythm.{key} is true but the file keeps no {needs}"
    return None
