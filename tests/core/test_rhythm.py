import numpy as np
import pytest

from rlanimate_addon.core import rhythm
from rlanimate_addon.core.errors import RLAnimateError


def test_signals_swing_at_the_rhythm_inside_its_envelope_only():
    wave = rhythm.Rhythm(frequency=0.08, start=0.25, stop=0.75, phase=0.3, ramp=9.0)
    s = rhythm.signals(wave, 121)  # frames 30 .. 90 swing
    amplitude = np.hypot(s[:, 0], s[:, 1])
    assert s.shape == (121, 2)
    assert np.all(amplitude[:31] == 0.0) and np.all(amplitude[90:] == 0.0)
    assert np.allclose(amplitude[39:82], 1.0)
    phase = np.unwrap(np.arctan2(s[39:82, 0], s[39:82, 1]))
    assert np.allclose(np.diff(phase), 2 * np.pi * 0.08)  # the frequency, in cycles per frame
    assert np.isclose(np.arctan2(s[39, 0], s[39, 1]), np.angle(np.exp(1j * (0.3 + 2 * np.pi * 0.08 * 9))))


def _training_rhythms():
    e = np.linspace(0.0, 1.0, 11)
    wobble = np.sin(7.0 * e)  # residuals around the line
    rhythms = [rhythm.Rhythm(0.08 - 0.01 * x + 0.002 * w, 0.25 + 0.05 * x, 0.7 - 0.04 * w, 0.2 + 0.1 * w, 9.0)
               for x, w in zip(e, wobble)]
    return e, rhythms


def test_the_model_regresses_each_parameter_on_the_exaggeration_and_draws_its_mean_without_a_seed():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    assert np.isclose(model.lines["start"]["slope"], 0.05) and np.isclose(model.lines["start"]["sd"], 0.0, atol=1e-12)
    mean = model.draw(0.5)
    assert np.isclose(mean.start, 0.275) and mean == model.draw(0.5)
    assert mean.frequency == pytest.approx(model.lines["frequency"]["intercept"] + 0.5 * model.lines["frequency"]["slope"])


def test_seeded_draws_differ_stay_within_the_training_residuals_and_repeat():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    draws = [model.draw(0.3, seed) for seed in range(1, 30)]
    assert draws[0] == model.draw(0.3, 1)
    assert len({d.phase for d in draws}) == len(draws)
    line = model.lines["frequency"]
    mean = line["intercept"] + 0.3 * line["slope"]
    assert all(mean + line["low"] - 1e-12 <= d.frequency <= mean + line["high"] + 1e-12 for d in draws)
    assert np.ptp([d.frequency for d in draws]) > 0.5 * (line["high"] - line["low"])


def test_the_model_round_trips_through_its_dict_and_refuses_a_broken_one():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    again = rhythm.RhythmModel.from_dict(model.to_dict())
    assert again.draw(0.4, 5) == model.draw(0.4, 5)
    broken = model.to_dict()
    del broken["lines"]["stop"]
    with pytest.raises(RLAnimateError, match="wave_rhythm"):
        rhythm.RhythmModel.from_dict(broken)
    with pytest.raises(RLAnimateError, match="wave_rhythm"):
        rhythm.RhythmModel.from_dict({**model.to_dict(), "ramp": float("nan")})
    with pytest.raises(RLAnimateError, match="at least 2"):
        rhythm.RhythmModel.fit([0.5], rhythms[:1])
