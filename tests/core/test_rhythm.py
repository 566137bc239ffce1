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
    far = model.draw(3.0).frequency  # far from all: the Gaussian's tail weighs the nearest waves most
    assert np.mean([r.frequency for r in rhythms[-4:]]) < far <= rhythms[-1].frequency


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
    with pytest.raises(RLAnimateError, match="tempo_bandwidth"):
        rhythm.RhythmModel.from_dict({**model.to_dict(), "tempo_bandwidth": 0.0})
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


def test_each_style_plays_its_own_phase_and_files_without_phases_the_mean_of_all():
    e, rhythms = _styles_with_their_own_phase()
    model = rhythm.RhythmModel.fit(e, rhythms).with_settings(bandwidth=0.05)  # narrower than the styles' spacing
    assert model.typical_tempo
    assert abs(model.phase) == pytest.approx(np.pi, abs=0.01)  # the mean of all twelve: no style's phase
    assert model.draw(0.215).phase == pytest.approx(2.5, abs=0.05)  # the style's own, not the mean of all
    assert model.draw(0.415).phase == pytest.approx(-2.5, abs=0.05)
    assert model.draw(0.915).phase == pytest.approx(0.0, abs=0.05)
    older = {key: value for key, value in model.to_dict().items() if key not in ("phases", "typical_tempo")}
    legacy = rhythm.RhythmModel.from_dict(older)
    assert not legacy.typical_tempo
    assert legacy.draw(0.215).phase == legacy.draw(0.915).phase == pytest.approx(model.phase)
    assert model.with_settings(typical_tempo=False).draw(0.215) == legacy.draw(0.215)
    assert model.with_settings(bandwidth=0.02).weights(0.215).max() > model.weights(0.215).max()


def _two_styles_of_one_exaggeration():
    """At exaggeration 0.5, five slow waves (0.03 cycles a frame) and three fast ones (0.06) that start and
    stop at other times and phases, as real masculine and normal waves do; a fast style far away."""
    e, rhythms = [], []
    for exaggeration, rate, start, stop, phase, takes in ((0.5, 0.03, 0.1, 0.8, 1.0, 5), (0.5, 0.06, 0.3, 0.6, -2.0, 3),
                                                          (0.9, 0.07, 0.05, 0.9, 0.0, 4)):
        for take in range(takes):
            e.append(exaggeration + 0.005 * take)
            rhythms.append(rhythm.Rhythm(rate * (1.0 + 0.02 * take), start, stop, phase + 0.05 * take, 9.0))
    return np.array(e), rhythms


def test_the_typical_tempo_is_one_styles_not_the_mean_of_two():
    e, rhythms = _two_styles_of_one_exaggeration()
    model = rhythm.RhythmModel.fit(e, rhythms)
    typical = model.draw(0.51)
    assert typical.frequency == pytest.approx(0.0312, rel=0.03)  # the slow style's, the commoner one
    assert (typical.start, typical.stop) == pytest.approx((0.1, 0.8), abs=0.01)
    assert typical.phase == pytest.approx(1.1, abs=0.1)
    fast = model.draw(0.51, tempo=0.062)  # a named tempo picks the style that swings at it
    assert fast.frequency == 0.062
    assert (fast.start, fast.stop) == pytest.approx((0.3, 0.6), abs=0.01)
    assert fast.phase == pytest.approx(-1.95, abs=0.1)
    mean = model.with_settings(typical_tempo=False).draw(0.51)
    assert 0.04 < mean.frequency < 0.05  # the mean of the two rates: a rate neither style swings at
    seeded = {model.draw(0.51, seed).frequency for seed in range(1, 30)}
    assert seeded <= {r.frequency for r in rhythms[:5]} and len(seeded) >= 3  # seeds vary within the style


def test_the_rhythm_settings_round_trip_and_broken_ones_are_refused():
    e, rhythms = _two_styles_of_one_exaggeration()
    model = rhythm.RhythmModel.fit(e, rhythms)
    for settings in (model, model.with_settings(typical_tempo=False), model.with_settings(tempo_bandwidth=0.5)):
        again = rhythm.RhythmModel.from_dict(settings.to_dict())
        assert again.typical_tempo == settings.typical_tempo and again.draw(0.51) == settings.draw(0.51)
        assert again.tempo_bandwidth == settings.tempo_bandwidth
    unkept = {key: value for key, value in model.to_dict().items() if key != "tempo_bandwidth"}
    assert rhythm.RhythmModel.from_dict(unkept).tempo_bandwidth == pytest.approx(np.log(1.25))  # files before: theirs
    wide = model.with_settings(tempo_bandwidth=np.log(2.5))  # so wide that the fast style weighs in the slow one's
    assert wide.draw(0.51).frequency > 1.05 * model.draw(0.51).frequency
    older = {key: value for key, value in model.to_dict().items() if key not in ("phases", "typical_tempo")}
    for broken in ({**older, "typical_tempo": True}, {**model.to_dict(), "phases": [0.1, 0.2]},
                   {**model.to_dict(), "typical_tempo": "yes"}, {**model.to_dict(), "by_arm": True},
                   {**model.to_dict(), "arms": ["LEFT"] * len(e), "by_arm": "yes"}):
        with pytest.raises(RLAnimateError, match="wave_rhythm"):
            rhythm.RhythmModel.from_dict(broken)


@pytest.mark.parametrize("field, value, named", [
    (None, "fast", "wave_rhythm is a string"), (None, [1.0, 2.0], "wave_rhythm is a list"),
    (None, 3, "wave_rhythm is a number"), ("examples", [["0.5", 0.07, 0.2, 0.8]] * 3, "wave_rhythm.examples"),
    ("examples", {"a": 1}, "wave_rhythm.examples"), ("phase", "1.5", "wave_rhythm.phase"),
    ("phase", True, "wave_rhythm.phase"), ("phase", 10 ** 400, "wave_rhythm.phase"),
    ("ramp", [9.0], "wave_rhythm.ramp"), ("bandwidth", -0.1, "wave_rhythm.bandwidth"),
    ("tempo_bandwidth", "x", "wave_rhythm.tempo_bandwidth"), ("phases", "x", "wave_rhythm.phases"),
    ("phases", [[0.1]] * 8, "wave_rhythm.phases"), ("arms", [["LEFT"]] * 8, "wave_rhythm.arms"),
    ("arms", "LEFT", "wave_rhythm.arms"), ("arms", 5, "wave_rhythm.arms"),
    ("typical_tempo", 1, "wave_rhythm.typical_tempo"), ("by_arm", "yes", "wave_rhythm.by_arm")])
def test_every_field_of_the_model_is_checked_for_its_type_and_named(field, value, named):
    e, rhythms = _training_rhythms()
    values = value if field is None else {**rhythm.RhythmModel.fit(e, rhythms).to_dict(), field: value}
    assert rhythm.invalid_field(values).startswith(named)
    with pytest.raises(RLAnimateError, match=named.replace(".", r"\.")):
        rhythm.RhythmModel.from_dict(values)


def test_a_requested_tempo_sets_the_rate_and_the_training_waves_near_it_the_rest():
    e, rhythms = _training_rhythms()
    model = rhythm.RhythmModel.fit(e, rhythms)
    for seed in (None, 5):  # a little faster than the style near 0.52: the tempo sets the rate, that style the rest
        own, asked = model.draw(0.52, seed), model.draw(0.52, seed, tempo=0.032)
        assert asked.frequency == 0.032
        assert (asked.start, asked.stop, asked.ramp) == pytest.approx((own.start, own.stop, own.ramp))
    assert 0.0 < model.draw(0.52).phase < model.draw(0.52, tempo=0.032).phase < 0.9  # within the style's takes'
    slower, faster = model.draw(0.52, tempo=0.066), model.draw(0.52, tempo=0.082)  # two other styles' rates
    assert (slower.start, slower.stop) == pytest.approx((0.05, 0.9), abs=0.02)  # 0.9's (0.07), not 0.52's
    assert (faster.start, faster.stop) == pytest.approx((0.1, 0.5), abs=0.04)  # 0.1's (0.075-0.08)
    assert model.tempo_range() == pytest.approx((0.028 / rhythm.TEMPO_MARGIN, 0.075 * 1.06 * rhythm.TEMPO_MARGIN))


def _two_arms_of_one_exaggeration():
    """At exaggeration 0.5, left-arm takes that swing slowly and right-arm takes of another style that swing
    fast, and a right-arm style far away."""
    e, rhythms, arms = [], [], []
    for exaggeration, rate, phase, arm in ((0.5, 0.03, 1.0, "LEFT"), (0.5, 0.06, -2.0, "RIGHT"),
                                           (0.9, 0.07, 0.0, "RIGHT")):
        for take in range(4):
            e.append(exaggeration + 0.005 * take)
            rhythms.append(rhythm.Rhythm(rate * (1.0 + 0.02 * take), 0.1, 0.8, phase, 9.0))
            arms.append(arm)
    return np.array(e), rhythms, arms


def test_with_by_arm_a_request_weighs_the_waves_of_its_own_arm():
    e, rhythms, arms = _two_arms_of_one_exaggeration()
    pooled = rhythm.RhythmModel.fit(e, rhythms, arms)
    assert pooled.by_arm == rhythm.BY_ARM and pooled.arms == tuple(arms)
    model = pooled.with_settings(by_arm=True)
    left, right = model.draw(0.51, arm="LEFT"), model.draw(0.51, arm="RIGHT")
    assert left.frequency == pytest.approx(0.0309, rel=0.02) and left.phase == pytest.approx(1.0, abs=0.01)
    assert right.frequency == pytest.approx(0.0618, rel=0.02) and right.phase == pytest.approx(-2.0, abs=0.01)
    assert model.weights(0.51, arm="LEFT")[4:].sum() == 0.0  # no right-arm wave weighs in a left-arm request
    assert {model.draw(0.51, seed, arm="LEFT").frequency for seed in range(1, 20)} <= {r.frequency for r in rhythms[:4]}
    unpooled = pooled.with_settings(by_arm=False)  # both arms' waves, whichever arm asks
    assert model.draw(0.51) == unpooled.draw(0.51, arm="LEFT") == unpooled.draw(0.51, arm="RIGHT")
    assert model.with_settings(bandwidth=0.02).arms == model.arms and model.with_settings(bandwidth=0.02).by_arm
    again = rhythm.RhythmModel.from_dict(model.to_dict())
    assert again.arms == tuple(arms) and again.by_arm and again.draw(0.51, arm="RIGHT") == right
    for broken in (arms[:-1], arms[:-1] + ["MIDDLE"]):
        with pytest.raises(RLAnimateError, match="wave_rhythm.arms must be null or a list of 12 arms"):
            rhythm.RhythmModel.from_dict({**model.to_dict(), "arms": broken})
