"""The paper's score and smoothness (core.metrics): hand-computed cases, scipy equivalence, calibration."""
import math

import numpy as np
import pytest
from scipy.signal import savgol_filter

from rlanimate_addon.core import metrics
from rlanimate_addon.core.easing import minimum_jerk
from rlanimate_addon.core.errors import RLAnimateError

FPS = 30
JOINTS = 10


def gesture(rng, frames, reach, wave_hz=0.0):
    """(F, 10, 3) synthetic gesture: joints rise with minimum-jerk timing, hold (optionally waving), return.

    Joints further down the arm move further, as the collars, shoulders, elbows, wrists and finger
    bases of a real gesture do.
    """
    t = np.arange(frames) / FPS
    duration = frames / FPS
    envelope = minimum_jerk(t / (0.3 * duration)) - minimum_jerk((t - 0.7 * duration) / (0.3 * duration))
    rest = rng.normal(0.0, 0.3, (JOINTS, 3)) + (0.0, 0.0, 1.4)
    direction = rng.normal(size=(JOINTS, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    weight = reach * np.linspace(0.05, 0.9, JOINTS)[:, None]  # (10, 1)
    positions = rest + envelope[:, None, None] * direction * weight
    if wave_hz:
        side = rng.normal(size=3)
        side /= np.linalg.norm(side)
        swing = 0.4 * np.sin(2 * np.pi * wave_hz * t) * envelope  # (F,)
        positions = positions + swing[:, None, None] * side * weight
    return positions


def reference_clips():
    rng = np.random.default_rng(7)
    clips = [gesture(rng, frames, reach) for frames, reach in [(45, 0.5), (90, 0.6), (150, 0.8), (240, 0.3)]]
    clips += [gesture(rng, frames, reach, hz) for frames, reach, hz in
              [(60, 0.3, 2.0), (90, 0.6, 3.0), (120, 1.0, 3.0), (240, 0.3, 2.5)]]
    return clips


# --- score ---------------------------------------------------------------------------------------

def test_frame_errors_sum_absolute_differences_over_joints_and_axes():
    reference = np.zeros((2, JOINTS, 3))
    generated = reference.copy()
    generated[0, 3] = (0.01, -0.02, 0.03)  # 6 cm of L1 error in frame 0
    generated[1, :, 2] = -0.001  # 1 mm on every joint's z in frame 1
    np.testing.assert_allclose(metrics.frame_errors(generated, reference), [0.06, 0.01])


def test_score_of_a_perfect_imitation_is_100():
    clip = reference_clips()[0]
    assert metrics.score(clip, clip) == 100.0


def test_score_without_penalty_is_100_minus_mean_frame_error():
    reference = np.zeros((4, JOINTS, 3))
    generated = reference.copy()
    generated[:, 0, 0] = [0.1, 0.2, 0.3, 0.4]  # every frame error <= 1 m: no penalty
    assert metrics.score(generated, reference) == pytest.approx(100.0 - (0.1 + 0.2 + 0.3 + 0.4) / 4)


def test_score_adds_the_log_penalty_per_frame_for_errors_over_one_metre():
    reference = np.zeros((2, JOINTS, 3))
    generated = reference.copy()
    generated[0, 0, 0] = 2.0  # error 2 m: penalty log_1.01(2)
    generated[1, 0, 1] = 0.5  # error 0.5 m: no penalty
    total = 2.0 + 0.5 + math.log(2.0) / math.log(1.01)
    assert metrics.score(generated, reference) == pytest.approx(100.0 - total / 2)


def test_penalty_is_zero_at_and_below_one_metre_and_handles_zero_error():
    np.testing.assert_array_equal(metrics.frame_penalties([0.0, 0.5, 1.0]), [0.0, 0.0, 0.0])
    assert metrics.frame_penalties([1.01])[0] == pytest.approx(1.0)


def test_score_rejects_mismatched_lengths_with_a_fix():
    with pytest.raises(RLAnimateError, match="same number of frames"):
        metrics.score(np.zeros((5, JOINTS, 3)), np.zeros((6, JOINTS, 3)))


def test_score_rejects_nan_positions():
    bad = np.zeros((5, JOINTS, 3))
    bad[2, 1, 0] = np.nan
    with pytest.raises(RLAnimateError, match="NaN"):
        metrics.score(bad, np.zeros((5, JOINTS, 3)))


# --- Savitzky-Golay ------------------------------------------------------------------------------

@pytest.mark.parametrize("window, order", [(5, 2), (7, 3), (9, 6), (11, 4)])
@pytest.mark.parametrize("frames", [11, 12, 60])
def test_numpy_savgol_equals_scipy(window, order, frames):
    values = np.random.default_rng(frames + window).normal(size=(frames, JOINTS, 3))
    expected = savgol_filter(values, window, order, axis=0)
    np.testing.assert_allclose(metrics.savgol_smooth(values, window, order), expected, atol=1e-10)


def test_default_filter_equals_scipy_on_a_gesture():
    clip = reference_clips()[5]
    expected = savgol_filter(clip, metrics.SMOOTHING_WINDOW, metrics.SMOOTHING_ORDER, axis=0)
    np.testing.assert_allclose(metrics.savgol_smooth(clip), expected, atol=1e-10)


def test_smoothness_rejects_clips_shorter_than_the_window():
    with pytest.raises(RLAnimateError, match="longer clip"):
        metrics.smoothness(np.zeros((metrics.SMOOTHING_WINDOW - 1, JOINTS, 3)))


# --- smoothness calibration ------------------------------------------------------------------------

def test_smooth_minimum_jerk_reference_clips_score_at_least_99_5():
    for clip in reference_clips():
        assert metrics.smoothness(clip) >= 99.5


def test_five_millimetres_of_jitter_drops_every_clip_below_the_artefact_threshold():
    rng = np.random.default_rng(11)
    for clip in reference_clips():
        for _ in range(3):
            jittered = clip + rng.normal(0.0, 0.005, clip.shape)
            assert metrics.smoothness(jittered) < metrics.ARTEFACT_THRESHOLD


def test_smoothness_does_not_depend_on_the_character_size():
    rng = np.random.default_rng(3)
    clip = reference_clips()[2] + rng.normal(0.0, 0.002, (150, JOINTS, 3))
    assert metrics.smoothness(2.5 * clip) == pytest.approx(metrics.smoothness(clip), abs=1e-9)


def test_more_jitter_scores_lower_and_a_still_pose_scores_100():
    rng = np.random.default_rng(5)
    clip = reference_clips()[1]
    noise = rng.normal(0.0, 1.0, clip.shape)
    scores = [metrics.smoothness(clip + sigma * noise) for sigma in (0.0, 0.001, 0.003, 0.01)]
    assert scores == sorted(scores, reverse=True)
    assert metrics.smoothness(np.ones((30, JOINTS, 3))) == 100.0
