"""Specs and style."""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GestureSpec:
    """What to perform. `target` (3,) in the character frame for a target behaviour (POINT, GUIDE);
    `exaggeration` in [0, 1] for an intensity one (WAVE, RAISE_HAND). `seed` picks the style (timing and
    posture variation)."""
    behaviour: str
    arm: str
    target: tuple[float, ...] | None = None
    exaggeration: float | None = None
    seed: int = 0


@dataclass(frozen=True)
class Style:
    """Moderate per-clip variation: the agent sees only t/N and the label, so timing stays close."""
    tempo: float          # scales every duration
    lead_in: float        # s in the neutral pose before anything moves
    hold: float           # s of pointing hold
    anticipation: float   # wind-up, as a fraction of the stroke
    overshoot: float      # past the key pose before settling, as a fraction of the stroke
    swivel: float         # rad added to the natural elbow swivel
    extension: float      # shoulder-to-wrist distance / arm length at the hold
    palm_roll: float      # rad the pointing palm turns from facing down towards the body
    head_tilt: float      # rad of friendly head tilt
    wave_frequency: float  # Hz
    wave_cycles: int


def draw_style(seed):
    """The style of clip `seed`, deterministic."""
    rng = np.random.default_rng(np.random.SeedSequence([0x5EED, int(seed)]))
    return Style(
        tempo=float(np.clip(rng.normal(1.0, 0.04), 0.92, 1.08)),
        lead_in=float(rng.uniform(0.25, 0.4)),
        hold=float(rng.uniform(0.75, 1.0)),
        anticipation=float(rng.uniform(0.04, 0.07)),
        overshoot=float(rng.uniform(0.025, 0.045)),
        swivel=float(rng.uniform(-0.12, 0.12)),
        extension=float(rng.uniform(0.975, 0.99)),
        palm_roll=float(rng.uniform(0.35, 0.65)),
        head_tilt=float(rng.uniform(0.04, 0.1)),
        wave_frequency=float(rng.uniform(2.2, 2.7)),
        wave_cycles=int(rng.integers(3, 5)),
    )
