"""Behaviour metrics (core.behaviour_metrics) on hand-made arms: a sine wave, a still arm, a ramp."""
import numpy as np
import pytest

from rlanimate_addon.core import behaviour_metrics as bm
from rlanimate_addon.core import kinematics, metrics, skeleton, spaces
from rlanimate_addon.core.behaviours import INTENSITY, TARGET, Behaviour
from rlanimate_addon.core.errors import RLAnimateError

FPS = 30
JOINT = {name: k for k, (name, _) in enumerate(skeleton.DESCRIPTION_JOINTS)}
REST = np.array([skeleton.BONE_BY_NAME[bone].head for _, bone in skeleton.DESCRIPTION_JOINTS])  # (10, 3)
SHOULDER = REST[JOINT["right_shoulder"]]
UPPER, FOREARM = 0.28, 0.25


def right_arm(elbow, wrist):
    """(F, 10, 3) description joints: the right elbow and wrist on the given (F, 3) paths, the rest
    still at the rest pose, the index base 8 cm past the wrist along the forearm."""
    clip = np.repeat(REST[None], len(wrist), axis=0)
    clip[:, JOINT["right_elbow"]] = elbow
    clip[:, JOINT["right_wrist"]] = wrist
    forearm = (wrist - elbow) / np.linalg.norm(wrist - elbow, axis=1, keepdims=True)
    clip[:, JOINT["right_index_base"]] = wrist + 0.08 * forearm
    return clip


def raised_wave(frames=90, hz=2.5, sway=0.5, phase=0.0, start=0):
    """The right upper arm out to the side, the forearm up and swaying about the elbow by `sway`
    radians at `hz` (still and upright before frame `start`)."""
    t = np.clip(np.arange(frames) - start, 0, None) / FPS
    angle = sway * np.sin(2 * np.pi * hz * t + phase) * (np.arange(frames) >= start)
    elbow = np.broadcast_to(SHOULDER + (-UPPER, 0.0, 0.0), (frames, 3))
    wrist = elbow + FOREARM * np.stack([-np.sin(angle), np.zeros(frames), np.cos(angle)], axis=1)
    return right_arm(elbow, wrist)


def hanging_arm(frames=90):
    elbow = np.broadcast_to(SHOULDER + (0.0, 0.0, -UPPER), (frames, 3))
    return right_arm(elbow, elbow + (0.0, 0.0, -FOREARM))


def test_sine_wave_strokes_cycles_frequency_and_swing():
    measures = bm.wave_measures(raised_wave(frames=90, hz=2.5, sway=0.5), "RIGHT")
    assert measures["hand_up_s"] == pytest.approx(3.0)
    # 7.5 cycles have 15 extrema: 14 legs between them plus the partial legs from the first frame
    # and to the last, each longer than the threshold
    assert measures["strokes"] == 16
    assert measures["cycles"] == 8
    assert measures["frequency"] == pytest.approx(2.5, rel=0.01)
    assert measures["swing"] == pytest.approx(2 * FOREARM * np.sin(0.5), rel=0.05)


def test_still_raised_arm_is_up_but_does_not_wave():
    measures = bm.wave_measures(raised_wave(sway=0.0), "RIGHT")
    assert measures["hand_up_s"] == pytest.approx(3.0)
    assert measures["strokes"] == measures["cycles"] == 0
    assert measures["swing"] == 0.0 and measures["frequency"] == 0.0


def test_hanging_arm_never_has_the_hand_up():
    measures = bm.wave_measures(hanging_arm(), "RIGHT")
    assert measures["hand_up_s"] == 0.0 and measures["strokes"] == 0
    assert measures["hand_height"] == pytest.approx(0.0, abs=1e-9)  # the wrist hangs as low as it can


def test_strokes_below_the_threshold_do_not_count():
    width = bm.shoulder_width(raised_wave())
    small = np.arcsin(0.9 * bm.STROKE_FRACTION * width / FOREARM / 2)  # legs just under the threshold
    assert bm.wave_measures(raised_wave(sway=small), "RIGHT")["strokes"] == 0
    assert bm.wave_measures(raised_wave(sway=1.2 * small), "RIGHT")["strokes"] > 0


def test_ramp_is_one_stroke_and_no_cycle():
    frames = 60
    elbow = np.broadcast_to(SHOULDER + (-UPPER, 0.0, 0.0), (frames, 3))
    angle = np.linspace(-0.6, 0.6, frames)  # the forearm tips steadily from one side to the other
    wrist = elbow + FOREARM * np.stack([-np.sin(angle), np.zeros(frames), np.cos(angle)], axis=1)
    measures = bm.wave_measures(right_arm(elbow, wrist), "RIGHT")
    assert measures["strokes"] == 1 and measures["cycles"] == 0 and measures["frequency"] == 0.0
    assert measures["swing"] == pytest.approx(2 * FOREARM * np.sin(0.6))


def test_turning_points_keep_legs_at_least_the_threshold():
    signal = np.array([0.0, 0.02, 0.1, 0.05, 0.09, -0.1, -0.05, 0.2])
    pivots = bm.turning_points(signal, 0.08)
    assert pivots == [0, 2, 5, 7]
    assert np.all(np.abs(np.diff(signal[pivots])) >= 0.08)
    assert bm.turning_points(np.zeros(10), 0.01) == []


def test_copied_wave_is_accepted_and_its_ratios_are_one():
    wave = raised_wave()
    comparison = bm.compare_wave(wave, wave, "RIGHT")
    for key in ("swing_ratio", "stroke_ratio", "frequency_ratio", "hand_height_ratio"):
        assert comparison[key] == pytest.approx(1.0)
    assert bm.wave_accepted(comparison)


def test_still_arm_wave_is_rejected():
    comparison = bm.compare_wave(raised_wave(sway=0.0), raised_wave(), "RIGHT")
    assert comparison["swing_ratio"] == 0.0 and comparison["generated"]["cycles"] == 0
    assert not bm.wave_accepted(comparison)


def test_class_mean_of_out_of_phase_waves_is_rejected_though_it_scores_well():
    """The per-frame mean of waves whose phases differ is a nearly still arm: the paper's score
    rates it close to a copy, the wave measures do not."""
    waves = [raised_wave(phase=p) for p in np.linspace(0, 2 * np.pi, 6, endpoint=False)]
    mean = np.mean(waves, axis=0)
    comparison = bm.compare_wave(mean, waves[0], "RIGHT")
    assert not bm.wave_accepted(comparison)
    assert comparison["swing_ratio"] < 0.1
    assert metrics.score(mean, waves[0]) > 97.0  # the paper's score barely notices


def test_half_as_fast_wave_fails_on_frequency_only():
    comparison = bm.compare_wave(raised_wave(hz=1.25), raised_wave(hz=2.5), "RIGHT")
    assert comparison["frequency_ratio"] == pytest.approx(0.5, rel=0.05)
    assert comparison["generated"]["cycles"] >= bm.WAVE_MIN_CYCLES
    assert comparison["swing_ratio"] == pytest.approx(1.0, rel=0.1)
    assert not bm.wave_accepted(comparison)


def test_elevation_hanging_horizontal_and_raised():
    assert bm.elevation(hanging_arm(2), "RIGHT") == pytest.approx([0.0, 0.0])
    assert bm.elevation(raised_wave(2), "RIGHT") == pytest.approx([90.0, 90.0])
    frames = 31
    angle = np.linspace(0.0, np.pi, frames)  # a ramp from hanging to straight up, in the side plane
    elbow = SHOULDER + UPPER * np.stack([-np.sin(angle), np.zeros(frames), -np.cos(angle)], axis=1)
    clip = right_arm(elbow, elbow + (elbow - SHOULDER) * FOREARM / UPPER)
    np.testing.assert_allclose(bm.elevation(clip, "RIGHT"), np.degrees(angle), atol=1e-6)
    result = bm.raise_lower(clip, hanging_arm(frames), "RIGHT")
    assert result["first_error"] == pytest.approx(0.0, abs=1e-6)
    assert result["last_error"] == pytest.approx(180.0)


def pointing_clip(frames=90, aim_error_deg=0.0):
    """The right arm rises (minimum-jerk) from hanging to straight out ahead, holds, and hangs again;
    returns the clip, the finger directions and a target 3 m along the line `aim_error_deg` off the finger."""
    t = np.arange(frames) / (frames - 1)
    up = np.clip(np.minimum(t / 0.3, (1 - t) / 0.3), 0, 1)
    up = up ** 3 * (10 - 15 * up + 6 * up ** 2)
    angle = up * np.pi / 2  # elevation from hanging to horizontal, pointing forward (-Y)
    direction = np.stack([np.zeros(frames), -np.sin(angle), -np.cos(angle)], axis=1)
    elbow = SHOULDER + UPPER * direction
    clip = right_arm(elbow, elbow + FOREARM * direction)
    error = np.radians(aim_error_deg)
    base = clip[frames // 2, JOINT["right_index_base"]]
    target = base + 3.0 * np.array([np.sin(error), -np.cos(error), 0.0])
    return clip, direction, target


def test_pointing_angle_and_hold():
    clip, finger, target = pointing_clip(aim_error_deg=0.0)
    measures = bm.point_measures(clip, finger, "RIGHT", target)
    assert measures["angle"] == pytest.approx(0.0, abs=1e-6)
    assert measures["hold_s"] == pytest.approx(1.2, abs=0.2)  # 40% of 3 s held still, plus the slow ends
    missed = bm.point_measures(*pointing_clip(aim_error_deg=5.0)[:2], "RIGHT", pointing_clip(aim_error_deg=5.0)[2])
    assert missed["angle"] == pytest.approx(5.0, abs=1e-6)


def test_the_hold_of_a_finger_path_does_not_depend_on_its_units():
    clip, _, _ = pointing_clip()
    base, width = clip[:, JOINT["right_index_base"]], bm.shoulder_width(clip)
    hold = bm.hold_frames(base, width)
    assert hold == bm.hold_run(clip, "RIGHT") and hold[1] - hold[0] > 30
    assert bm.hold_frames(100.0 * base + 7.0, 100.0 * width) == hold  # centimetres, elsewhere
    assert bm.hold_frames(base, 0.1 * width) != hold  # the speed threshold scales with the width


def test_a_point_that_never_holds_is_measured_at_its_apex():
    frames = 20  # rises and falls straight away: the finger never slows down past half its travel
    clip, finger, target = pointing_clip(frames)
    swept = 20.0 * np.sin(np.linspace(0.0, np.pi, frames)) + 3.0  # the arm sweeps fast through the apex
    measures = bm.point_measures(clip + swept[:, None, None] * (1.0, 0.0, 0.0), finger, "RIGHT", target)
    assert measures["hold_s"] == 0.0
    assert 0.0 < measures["angle"] < 180.0


def test_still_arm_has_no_short_hold_and_points_down():
    _, _, target = pointing_clip()
    still = hanging_arm(60)
    finger = np.broadcast_to((0.0, 0.0, -1.0), (60, 3))
    measures = bm.point_measures(still, finger, "RIGHT", target)
    assert measures["hold_s"] == pytest.approx(2.0)
    assert measures["angle"] > 80.0


def test_variation_is_the_mean_pairwise_distance():
    wave = raised_wave()
    assert bm.variation([wave, wave]) == 0.0
    shifted = wave + (0.01, 0.0, 0.0)
    assert bm.variation([wave, shifted, shifted]) == pytest.approx(2 / 3 * 0.01)
    with pytest.raises(RLAnimateError, match="same length"):
        bm.variation([wave, wave[:-1]])


def test_score_at_length_compares_with_the_time_scaled_reference():
    reference = raised_wave(frames=90, hz=2.0)
    faster = bm.resample(reference, 60)  # the same gesture in 2 s instead of 3
    assert bm.score_at_length(faster, reference) == pytest.approx(100.0)
    assert metrics.score(faster, reference[:60]) < 99.8  # two joints of ten move: small but clear


def test_aligned_score_forgives_timing_not_stillness():
    reference = raised_wave(frames=90, start=10)
    late = raised_wave(frames=90, start=16)  # the same wave 0.2 s later
    still = raised_wave(frames=90, sway=0.0)
    assert bm.aligned_score(late, reference) > 99.8
    assert metrics.score(late, reference) < bm.aligned_score(late, reference) - 0.25
    assert bm.aligned_score(still, reference) == pytest.approx(metrics.score(still, reference), abs=0.5)
    assert bm.aligned_score(still, reference) < bm.aligned_score(late, reference) - 0.1


def test_dtw_path_runs_corner_to_corner_monotonically():
    path = bm.dtw_path(raised_wave(frames=40), raised_wave(frames=50))
    assert tuple(path[0]) == (0, 0) and tuple(path[-1]) == (39, 49)
    assert np.all(np.diff(path, axis=0) >= 0) and np.all(np.diff(path, axis=0).sum(axis=1) >= 1)


def test_bad_input_is_named():
    with pytest.raises(RLAnimateError, match="description-joint positions"):
        bm.wave_measures(np.zeros((5, 3)), "RIGHT")
    with pytest.raises(RLAnimateError, match="LEFT or RIGHT"):
        bm.elevation(raised_wave(), "UP")


def test_compare_reads_descriptions_of_the_canonical_skeleton():
    """A wave and a point built from rotations through the numpy FK: a copy matches itself, a
    still arm misses."""
    frames = 60
    t = np.arange(frames) / FPS
    rotvecs = np.zeros((frames, len(skeleton.ACTION_JOINTS), 3))
    arm, forearm = skeleton.ACTION_JOINTS.index("RightArm"), skeleton.ACTION_JOINTS.index("RightForeArm")
    rotvecs[:, arm] = (0.0, 0.0, 0.3)  # upper arm a little raised
    rotvecs[:, forearm, 2] = -1.6 + 0.5 * np.sin(2 * np.pi * 2.5 * t)  # forearm up, swaying
    wave = kinematics.describe(rotvecs)
    still = kinematics.describe(np.zeros_like(rotvecs))
    copied = bm.compare(wave, wave, Behaviour("WAVE", INTENSITY), "RIGHT")
    assert copied["wave_accepted"] == 1.0 and copied["swing_ratio"] == pytest.approx(1.0)
    assert copied["elevation_first_error"] == 0.0
    assert bm.compare(still, wave, Behaviour("WAVE", INTENSITY), "RIGHT")["wave_accepted"] == 0.0
    assert bm.compare(wave, wave, Behaviour("SHAKE", INTENSITY, "wave"), "RIGHT") == copied, "measured as what it does"
    finger = bm.finger_direction(still, "RIGHT")
    base = spaces.description_joint_positions(still)[0, JOINT["right_index_base"]]
    pointed = bm.compare(still, still, Behaviour("POINT", TARGET), "RIGHT", target=base + 2.0 * finger[0])
    assert pointed["pointing_angle"] == pytest.approx(0.0, abs=1e-6) and pointed["hold_ratio"] == 1.0


def test_a_behaviour_without_measures_of_its_own_is_measured_by_its_kind():
    """A user's intensity gesture ("hello": a raised hand) by the hand's peak height and the other arm's rise; a
    target one by its aim at the target; a copy scores zero error, a still arm does not, and neither is measured
    as something it is not (no wave, no point measures)."""
    frames = 60
    rise = np.clip(np.arange(frames) / 20.0, 0.0, 1.0)[:, None]
    rotvecs = np.zeros((frames, len(skeleton.ACTION_JOINTS), 3))
    rotvecs[:, skeleton.ACTION_JOINTS.index("RightArm")] = rise * (1.2, 0.0, 0.0)  # the right arm goes up
    raised, still = kinematics.describe(rotvecs), kinematics.describe(np.zeros_like(rotvecs))
    copied = bm.compare(raised, raised, Behaviour("HELLO", INTENSITY), "RIGHT")
    assert copied["hand_height_error"] == 0.0 and copied["free_arm_rise"] == pytest.approx(0.0, abs=1e-9)
    assert "swing_ratio" not in copied and "pointing_angle" not in copied
    assert bm.compare(still, raised, Behaviour("HELLO", INTENSITY), "RIGHT")["hand_height_error"] > 0.3
    assert set(bm.compare(raised, raised, None, "RIGHT")) == {f"elevation_{k}" for k in (
        "first", "last", "reference_first", "reference_last", "first_error", "last_error")}, "no kind: elevation"
    positions = spaces.description_joint_positions(raised)
    shoulder, base = positions[0, JOINT["right_shoulder"]], positions[-1, JOINT["right_index_base"]]
    this_way = Behaviour("THIS_WAY", TARGET)
    aimed = bm.compare(raised, raised, this_way, "RIGHT", target=shoulder + 3.0 * (base - shoulder))
    assert aimed["aim_error"] == pytest.approx(0.0, abs=0.5) and aimed["reference_aim_error"] == aimed["aim_error"]
    assert bm.compare(still, raised, Behaviour("THIS_WAY", TARGET), "RIGHT",
                      target=shoulder + 3.0 * (base - shoulder))["aim_error"] > 30.0
    assert "aim_error" not in bm.compare(raised, raised, Behaviour("THIS_WAY", TARGET), "RIGHT"), "no target, no aim"
