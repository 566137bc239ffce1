"""What tempo a label can reach: a test style whose labels lie only among other styles' fast waves is out of every
rule's reach, while one whose own waves were trained on is within it."""
from types import SimpleNamespace

import pytest

from rlanimate_addon.core import rhythm
from rlanimate_addon.core.errors import RLAnimateError
from trainer.evaluation.label_reach import label_reach

FPS = 30.0


def _wave(style, exaggeration, hz, arm="RIGHT", fps=FPS):
    """A swinging wave's (clip, Rhythm) pair, as wave_rhythm.swinging reads it."""
    clip = SimpleNamespace(style=style, attributes=exaggeration, arm=arm, fps=fps)
    return clip, rhythm.Rhythm(hz / fps, 0.1, 0.9, 0.3, 9.0)


def _training():
    """A fast style at labels 0.1-0.15 and a slow one at 0.6-0.65, each arm."""
    return [_wave(style, e + 0.01 * k, hz * (1.0 + 0.02 * k), arm)
            for style, e, hz in (("fast", 0.1, 2.4), ("slow", 0.6, 0.8)) for k in range(6)
            for arm in ("LEFT", "RIGHT")]


def test_a_style_between_the_training_labels_that_swings_slowly_is_out_of_reach():
    test = [_wave("unseen", 0.25 + 0.01 * k, 0.8) for k in range(4)] + [_wave("slow", 0.62, 0.85)]
    reach = label_reach(_training(), test)
    unseen, slow = reach["styles"]["unseen"], reach["styles"]["slow"]
    assert unseen["takes"] == 4 and unseen["labels"] == pytest.approx((0.25, 0.28))
    assert unseen["tempo_hz"] == pytest.approx(0.8)
    # Within 0.05 of its labels lie none; within 0.1, the fast style's waves (2.4-2.6 Hz), none near 0.8 Hz.
    assert unseen["near"]["0.05"] == {"waves": 0, "styles": [], "in_reach": 0, "in_reach_styles": []}
    assert unseen["near"]["0.1"]["waves"] > 0 and unseen["near"]["0.1"]["styles"] == ["fast"]
    assert unseen["near"]["0.1"]["in_reach"] == 0
    assert unseen["near"]["0.2"]["in_reach_styles"] == []
    # Every kernel reads its rate from the fast waves (the nearer ones), so no rule reaches 0.8 Hz...
    assert unseen["rules"]["in_band"] == 0 and unseen["rules"]["lowest"] > 1.25
    # ... while the style trained on is played at its own rate by most of them.
    assert slow["near"]["0.05"]["in_reach_styles"] == ["slow"] and slow["rules"]["in_band"] > reach["rules"] // 2
    assert reach["rules"] == 72 and reach["in_band_in_every_style"] == 0


def test_a_test_of_trained_styles_alone_is_reached_by_some_rules_in_every_style():
    reach = label_reach(_training(), [_wave("fast", 0.12, 2.5), _wave("slow", 0.62, 0.85, "LEFT")])
    assert 0 < reach["in_band_in_every_style"] <= reach["rules"]


def test_training_waves_of_two_frame_rates_are_refused():
    training = _training() + [_wave("slow", 0.61, 0.8, fps=60.0)]
    with pytest.raises(RLAnimateError, match="one frame rate"):
        label_reach(training, [_wave("slow", 0.62, 0.85)])
