"""The wave's rhythm as part of the objective: when the hand swings, and at what phase.

The paper's wave objective carries only the exaggeration (three times). Clips of the same
exaggeration swing at different phases, rates and counts, and nothing in that objective tells them
apart, so the per-frame regression of the animation model onto them averages out-of-phase swings
into a still arm. Here the wave's attributes are [exaggeration, A_t sin(phi_t), A_t cos(phi_t)]:

    phi_t = phase + 2 pi frequency (t - start)          frequency in cycles per frame
    A_t   = smoothstep((t - start) / ramp) * smoothstep((stop - t) / ramp)

with start and stop in frames (given as fractions of the gesture, so a longer gesture swings for
proportionally longer). During training the task module reads these from each clip
(trainer/motion/wave_rhythm.py); at play time `RhythmModel.draw` picks them from the training clips'
distribution: their regression on the exaggeration for `seed=None`, a seeded draw within the
training range otherwise, so seeds vary the phase, rate and number of swings.
"""
from dataclasses import asdict, dataclass

import numpy as np

from .errors import RLAnimateError

#: The parameters of a rhythm, each regressed on the exaggeration over the training clips.
PARAMETERS = ("frequency", "start", "stop")
#: A seeded draw keeps each parameter's residual within this many standard deviations (and within the
#: training clips' own range), so a varied wave stays a typical one: rate within about 10%.
DRAW_SDS = 1.5


@dataclass(frozen=True)
class Rhythm:
    frequency: float  # cycles per frame
    start: float  # the swing envelope starts rising, as a fraction of the gesture (t / (N - 1))
    stop: float  # ... and has fallen back to zero
    phase: float  # radians, at `start`
    ramp: float  # frames over which the envelope rises and falls

    def to_dict(self):
        return asdict(self)


def signals(rhythm, frame_count):
    """(N, 2) [A_t sin(phi_t), A_t cos(phi_t)] of `rhythm` over a gesture of `frame_count` frames."""
    t = np.arange(int(frame_count), dtype=np.float64)
    span = max(int(frame_count) - 1, 1)
    start, stop = rhythm.start * span, rhythm.stop * span
    envelope = _smoothstep((t - start) / rhythm.ramp) * _smoothstep((stop - t) / rhythm.ramp)
    phi = rhythm.phase + 2.0 * np.pi * rhythm.frequency * (t - start)
    return np.stack([envelope * np.sin(phi), envelope * np.cos(phi)], axis=1)


def _smoothstep(x):
    s = np.clip(x, 0.0, 1.0)
    return s * s * (3.0 - 2.0 * s)


class RhythmModel:
    """The training clips' rhythms as an agent file stores them (`to_dict` / `from_dict`).

    For each of PARAMETERS: a line on the exaggeration (intercept, slope) and the residuals' standard
    deviation and range; the phase's circular mean; the envelope ramp in frames.
    """

    def __init__(self, lines, phase, ramp):
        self.lines, self.phase, self.ramp = lines, float(phase), float(ramp)

    @classmethod
    def fit(cls, exaggerations, rhythms):
        """From the training clips' exaggerations (K,) and their Rhythms (K)."""
        e = np.asarray(exaggerations, dtype=np.float64)
        if len(e) < 2:
            raise RLAnimateError("Fitting the wave rhythm needs at least 2 wave clips whose hand swings side to "
                                 "side: add such wave clips.")
        design = np.stack([np.ones_like(e), e], axis=1)
        lines = {}
        for name in PARAMETERS:
            values = np.array([getattr(r, name) for r in rhythms])
            coefficients = np.linalg.lstsq(design, values, rcond=None)[0]
            residuals = values - design @ coefficients
            lines[name] = {"intercept": float(coefficients[0]), "slope": float(coefficients[1]),
                           "sd": float(residuals.std()), "low": float(residuals.min()),
                           "high": float(residuals.max())}
        phase = float(np.angle(np.mean(np.exp(1j * np.array([r.phase for r in rhythms])))))
        return cls(lines, phase, float(np.mean([r.ramp for r in rhythms])))

    def to_dict(self):
        return {"lines": self.lines, "phase": self.phase, "ramp": self.ramp}

    @classmethod
    def from_dict(cls, values):
        try:
            lines = {name: {key: float(values["lines"][name][key])
                            for key in ("intercept", "slope", "sd", "low", "high")} for name in PARAMETERS}
            model = cls(lines, float(values["phase"]), float(values["ramp"]))
        except (KeyError, TypeError, ValueError) as error:
            raise RLAnimateError(f"The agent's wave_rhythm metadata is invalid ({error!r}): re-export the "
                                 f"agent with trainer/agent/agent_export.py.") from error
        numbers = [v for line in lines.values() for v in line.values()] + [model.phase, model.ramp]
        if not np.all(np.isfinite(numbers)) or model.ramp <= 0:
            raise RLAnimateError("The agent's wave_rhythm metadata holds invalid numbers: re-export the agent.")
        return model

    def draw(self, exaggeration, seed=None):
        """The Rhythm for a wave of this exaggeration: the regression's mean for seed None, else a
        seeded draw (normal residuals, clipped to DRAW_SDS and to the training clips' range; any phase)."""
        rng = None if seed is None else np.random.default_rng(seed)
        values = {}
        for name in PARAMETERS:
            line = self.lines[name]
            mean = line["intercept"] + line["slope"] * float(exaggeration)
            residual = 0.0 if rng is None else float(np.clip(rng.normal(0.0, line["sd"]),
                                                             max(line["low"], -DRAW_SDS * line["sd"]),
                                                             min(line["high"], DRAW_SDS * line["sd"])))
            values[name] = mean + residual
        phase = self.phase if rng is None else float(rng.uniform(-np.pi, np.pi))
        start = float(np.clip(values["start"], 0.0, 1.0))
        stop = float(np.clip(values["stop"], start, 1.0))
        return Rhythm(max(values["frequency"], 0.0), start, stop, phase, self.ramp)
