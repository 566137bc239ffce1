"""Leave-one-out on training waves tells the typical tempo from the mean where one exaggeration holds two rates,
and sees no difference where it holds one."""
import numpy as np
import pytest

from rlanimate_addon.core import rhythm
from trainer.evaluation.rhythm_leave_one_out import leave_one_out


def _waves(second_rate):
    """Six slow waves and four at `second_rate` (cycles a frame), all of exaggeration about 0.5."""
    e, rhythms = [], []
    for k in range(10):
        rate = 0.03 if k < 6 else second_rate
        e.append(0.5 + 0.002 * k)
        rhythms.append(rhythm.Rhythm(rate * (1.0 + 0.01 * k), 0.1, 0.9, 0.5, 9.0))
    return np.array(e), rhythms, [150] * len(rhythms)


def test_the_typical_tempo_predicts_a_left_out_wave_where_the_mean_of_two_rates_predicts_none():
    typical, mean = (leave_one_out(*_waves(0.06), typical_tempo=flag) for flag in (True, False))
    assert typical["waves"] == 10
    assert typical["rate_within"] == pytest.approx(0.6)  # every slow wave, none of the fast ones
    assert mean["rate_within"] == 0.0  # ~0.042: 1.4x the slow waves' rate, 0.7x the fast ones'
    assert typical["median_log_rate_error"] < mean["median_log_rate_error"]
    assert typical["signal_correlation"] > mean["signal_correlation"] + 0.3


def test_with_one_rate_both_rules_predict_it():
    typical, mean = (leave_one_out(*_waves(0.03), typical_tempo=flag) for flag in (True, False))
    assert typical["rate_within"] == mean["rate_within"] == 1.0
    assert typical["signal_correlation"] > 0.9 and mean["signal_correlation"] > 0.9


def test_where_each_arm_swings_at_its_own_rate_the_arms_predict_every_left_out_wave():
    e, rhythms, frames = _waves(0.06)
    arms = ["LEFT"] * 6 + ["RIGHT"] * 4  # the slow waves are the left arm's, the fast ones the right arm's
    by_arm = leave_one_out(e, rhythms, frames, typical_tempo=True, arms=arms, by_arm=True)
    assert by_arm["rate_within"] == 1.0
    pooled = leave_one_out(e, rhythms, frames, typical_tempo=True, arms=arms, by_arm=False)
    assert by_arm["rate_within"] > pooled["rate_within"]
    assert pooled == leave_one_out(e, rhythms, frames, typical_tempo=True)  # by_arm off: the arms do not count
    assert leave_one_out(e, rhythms, frames, True, tempo_bandwidth=np.log(1.05))["waves"] == 10
