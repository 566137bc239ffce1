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
    """Three styles whose rates do not follow the exaggeration (as in the real capture: small waves fast,
    middling ones slow, big ones fast), four takes each."""
    styles = [(0.1, 0.075, 0.1, 0.5), (0.5, 0.028, 0.2, 0.8), (0.9, 0.07, 0.05, 0.9)]  # e, rate, start, stop
    e, rhythms = [], []
    for exaggeration, rate, start, stop in styles:
        for take in range(4):
            e.append(exaggeration + 0.01 * take)
            rhythms.append(rhythm.Rhythm(rate * (1.0 + 0.02 * take), start, stop, 0.3 * take, 9.0))
    return np.array(e), rhythms


def test_without_a_seed_a_request_plays_the_mean_rhythm_of_the_training_waves_near_its_exaggeration():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    for exaggeration, rate, start, stop in [(0.11, 0.075, 0.1, 0.5), (0.52, 0.028, 0.2, 0.8), (0.92, 0.07, 0.05, 0.9)]:
        mean = model.draw(exaggeration)
        assert mean.frequency == pytest.approx(rate, rel=0.05)  # a line through the three styles: 20-106% off
        assert (mean.start, mean.stop) == pytest.approx((start, stop), abs=1e-6)
        assert mean == model.draw(exaggeration)
    assert model.draw(3.0).frequency == pytest.approx(rhythms[-1].frequency, rel=1e-3)  # far from all: the nearest wave's


def test_seeded_draws_take_one_nearby_training_wave_at_any_phase_and_repeat():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    draws = [model.draw(0.51, seed) for seed in range(1, 30)]
    assert draws[0] == model.draw(0.51, 1)
    assert len({d.phase for d in draws}) == len(draws)
    nearby = {r.frequency for r in rhythms[4:8]}
    assert {d.frequency for d in draws} <= nearby and len({d.frequency for d in draws}) >= 3


def test_the_model_round_trips_through_its_dict_and_refuses_a_broken_one():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    again = rhythm.RhythmModel.from_dict(model.to_dict())
    assert again.draw(0.4, 5) == model.draw(0.4, 5)
    broken = model.to_dict()
    del broken["bandwidth"]
    with pytest.raises(RLAnimateError, match="wave_rhythm"):
        rhythm.RhythmModel.from_dict(broken)
    with pytest.raises(RLAnimateError, match="wave_rhythm"):
        rhythm.RhythmModel.from_dict({**model.to_dict(), "examples": [[0.5, 0.07, 0.2]] * 3})
    with pytest.raises(RLAnimateError, match="wave_rhythm"):
        rhythm.RhythmModel.from_dict({**model.to_dict(), "ramp": float("nan")})
    with pytest.raises(RLAnimateError, match="at least 2"):
        rhythm.RhythmModel.fit([0.5], rhythms[:1])


def _styles_with_their_own_phase():
    """Two styles of nearby exaggeration that start swinging at opposite phases, and a third far away."""
    e, rhythms = [], []
    for exaggeration, phase in ((0.2, 2.5), (0.4, -2.5), (0.9, 0.0)):
        for take in range(4):
            e.append(exaggeration + 0.01 * take)
            rhythms.append(rhythm.Rhythm(0.05, 0.1, 0.9, phase + 0.05 * (take - 1.5), 9.0))
    return np.array(e), rhythms


def test_nearby_phase_gives_the_mean_rhythm_the_phase_of_the_waves_near_the_request():
    e, rhythms = _styles_with_their_own_phase()
    everywhere = rhythm.RhythmModel.fit(e, rhythms)
    nearby = rhythm.RhythmModel.fit(e, rhythms, nearby_phase=True)
    assert everywhere.draw(0.215).phase == pytest.approx(everywhere.phase) == everywhere.draw(0.915).phase
    assert abs(everywhere.phase) == pytest.approx(np.pi, abs=0.01)  # the mean of all twelve: no style's phase
    assert nearby.draw(0.215).phase == pytest.approx(2.5, abs=0.05)  # the style's own, not the mean of all
    assert nearby.draw(0.415).phase == pytest.approx(-2.5, abs=0.05)
    assert nearby.draw(0.915).phase == pytest.approx(0.0, abs=0.05)
    assert nearby.draw(0.5).frequency == everywhere.draw(0.5).frequency  # only the phase is chosen differently
    assert nearby.draw(0.215, 4) == everywhere.draw(0.215, 4)  # seeded draws do not change
    assert everywhere.with_settings(nearby_phase=True).draw(0.215) == nearby.draw(0.215)
    assert everywhere.with_settings(bandwidth=0.02).weights(0.215).max() > everywhere.weights(0.215).max()


def test_nearby_phase_round_trips_and_files_without_phases_keep_the_mean_of_all():
    e, rhythms = _styles_with_their_own_phase()
    nearby = rhythm.RhythmModel.fit(e, rhythms, nearby_phase=True)
    again = rhythm.RhythmModel.from_dict(nearby.to_dict())
    assert again.nearby_phase and again.draw(0.215) == nearby.draw(0.215)
    older = {key: value for key, value in nearby.to_dict().items() if key not in ("phases", "nearby_phase")}
    assert rhythm.RhythmModel.from_dict(older).draw(0.215).phase == pytest.approx(nearby.phase)
    for broken in ({**older, "nearby_phase": True}, {**nearby.to_dict(), "phases": [0.1, 0.2]},
                   {**nearby.to_dict(), "nearby_phase": "yes"}):
        with pytest.raises(RLAnimateError, match="wave_rhythm"):
            rhythm.RhythmModel.from_dict(broken)


def test_a_requested_tempo_sets_the_rate_and_the_training_waves_the_rest():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    for seed in (None, 5):
        own, asked = model.draw(0.52, seed), model.draw(0.52, seed, tempo=0.05)
        assert asked.frequency == 0.05
        assert (asked.start, asked.stop, asked.phase, asked.ramp) == (own.start, own.stop, own.phase, own.ramp)
    assert model.tempo_range() == pytest.approx((0.028 / rhythm.TEMPO_MARGIN, 0.075 * 1.06 * rhythm.TEMPO_MARGIN))
