import numpy as np
import pytest

from rlanimate_addon.core import kinematics, skeleton, spaces
from rlanimate_addon.core.easing import minimum_jerk
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.rotations import matrix_to_rotvec, rotvec_to_matrix
from trainer.motion import synthesis as gs
from trainer.motion.synthesis.timing import blend_rotation


def heads_of(clip):
    return kinematics.head_positions(kinematics.pose_matrices(clip.rotvecs))  # (F, B, 3)


def joint(name):
    return kinematics.bone_index(name)


def random_target(rng, arm):
    """A target 1.5-4 m from the arm's shoulder, anywhere in the reachable front hemisphere."""
    sign = 1.0 if arm == "LEFT" else -1.0
    azimuth, elevation = rng.uniform(np.radians(-60), np.radians(95)), rng.uniform(np.radians(-35), np.radians(55))
    direction = np.array([sign * np.sin(azimuth) * np.cos(elevation), -np.cos(azimuth) * np.cos(elevation),
                          np.sin(elevation)])
    return skeleton.shoulder_rest_position(arm) + rng.uniform(1.5, 4.0) * direction


def point(arm, target, seed=0):
    return gs.synthesise(gs.GestureSpec("POINT", arm, target=tuple(target), seed=seed))


def wave(arm, exaggeration, seed=0):
    return gs.synthesise(gs.GestureSpec("WAVE", arm, exaggeration=exaggeration, seed=seed))


@pytest.mark.parametrize("arm", skeleton.ARMS)
def test_finger_line_passes_through_the_target_during_the_hold(arm):
    rng = np.random.default_rng()
    side = skeleton.ARM_PREFIX[arm]
    for _ in range(6):
        target = random_target(rng, arm)
        clip = point(arm, target, seed=int(rng.integers(1 << 30)))
        first, last = clip.phases["hold"]
        assert last - first >= 15  # at least half a second of hold
        heads = heads_of(clip)[first:last + 1]
        base, tip = heads[:, joint(side + "HandIndex1")], heads[:, joint(side + "HandIndex4")]
        finger = tip - base
        to_target = target - base
        cosine = np.sum(finger * to_target, 1) / np.linalg.norm(finger, axis=1) / np.linalg.norm(to_target, axis=1)
        assert np.degrees(np.arccos(np.clip(cosine, -1, 1))).max() <= 1.0
        # The base sits on the objective's ray, so the contract holds at any distance along it.
        direction = spaces.pointing_direction(arm, target)
        offset = base - skeleton.shoulder_rest_position(arm)
        off_ray = offset - np.outer(offset @ direction, direction)
        assert np.linalg.norm(off_ray, axis=1).max() < 1e-3


def test_every_clip_starts_and_ends_in_the_shared_neutral_pose():
    neutral = gs.neutral_pose()
    rng = np.random.default_rng()
    clips = [point("LEFT", random_target(rng, "LEFT"), 3), point("RIGHT", random_target(rng, "RIGHT"), 4),
             wave("LEFT", 0.1, 5), wave("RIGHT", 0.9, 6),
             gs.synthesise(gs.GestureSpec("GUIDE", "LEFT", target=(1.5, -2.0, 0.5), seed=7)),
             gs.synthesise(gs.GestureSpec("RAISE_HAND", "RIGHT", exaggeration=0.6, seed=8))]
    for clip in clips:
        assert set(clip.rotvecs) == set(gs.ANIMATED_BONES)
        for name, rotvecs in clip.rotvecs.items():
            np.testing.assert_allclose(rotvecs[0], neutral[name], atol=1e-9)
            np.testing.assert_allclose(rotvecs[-1], neutral[name], atol=1e-9)


def test_neutral_pose_hangs_the_arms_relaxed_at_the_sides():
    heads = kinematics.head_positions(kinematics.pose_matrices(gs.neutral_pose()))
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        shoulder, elbow, wrist = (heads[joint(side + b)] for b in ("Arm", "ForeArm", "Hand"))
        assert wrist[2] < elbow[2] < shoulder[2] - 0.2  # hanging
        assert sign * wrist[0] > 0.15  # beside the hip, not inside it
        upper, fore = elbow - shoulder, wrist - elbow
        bend = np.degrees(np.arccos(upper @ fore / np.linalg.norm(upper) / np.linalg.norm(fore)))
        assert 5 < bend < 30  # a slight elbow bend


def test_action_joints_stay_inside_the_action_bounds():
    rng = np.random.default_rng()
    low, high = spaces.DEFAULT_ACTION_BOUNDS[:, 0], spaces.DEFAULT_ACTION_BOUNDS[:, 1]
    clips = [point(arm, random_target(rng, arm), int(rng.integers(1 << 30))) for arm in skeleton.ARMS for _ in range(4)]
    clips += [wave(arm, e, int(rng.integers(1 << 30))) for arm in skeleton.ARMS for e in (0.0, 0.5, 1.0)]
    for clip in clips:
        flat = clip.action_rotvecs().reshape(clip.frames, -1)
        assert np.all(flat >= low) and np.all(flat <= high)


def test_index2_and_index3_stay_straight_and_pointing_curls_the_other_fingers():
    assert not any(name.endswith(("Index2", "Index3")) for name in gs.ANIMATED_BONES)
    clip = point("RIGHT", (-0.2, -2.5, 1.6), seed=1)
    hold = clip.phases["hold"][0]
    assert np.linalg.norm(clip.rotvecs["RightHandIndex1"][hold]) < 1e-6  # extended with the hand
    for finger in ("Middle", "Ring", "Pinky"):
        assert all(np.linalg.norm(clip.rotvecs[f"RightHand{finger}{k}"][hold]) > 0.8 for k in (1, 2))
    assert np.linalg.norm(clip.rotvecs["RightHandThumb3"][hold]) > 0.3


def test_wave_gets_wider_and_higher_with_exaggeration():
    for arm in skeleton.ARMS:
        side = skeleton.ARM_PREFIX[arm]
        heights, widths, shoulder_swings = [], [], []
        for seed, exaggeration in enumerate(np.linspace(0.0, 1.0, 5)):
            clip = wave(arm, exaggeration, seed)
            first, last = clip.phases["wave"]
            heads = heads_of(clip)[first:last + 1]
            wrist = heads[:, joint(side + "Hand")]
            upper = heads[:, joint(side + "ForeArm")] - heads[:, joint(side + "Arm")]
            upper /= np.linalg.norm(upper, axis=1, keepdims=True)
            mean = upper.mean(0) / np.linalg.norm(upper.mean(0))
            heights.append(wrist[:, 2].mean())
            widths.append(np.ptp(wrist[:, 0]))
            shoulder_swings.append(np.ptp(np.arccos(np.clip(upper @ mean, -1, 1))))  # whole-arm involvement
        assert np.all(np.diff(heights) > 0.03)
        assert np.all(np.diff(widths) > 0.02)
        assert np.all(np.diff(shoulder_swings) > 0.0)
        assert heights[0] > skeleton.shoulder_rest_position(arm)[2]  # the forearm is raised


def test_wave_oscillates_at_two_to_three_hertz():
    for seed in range(4):
        clip = wave("LEFT", 0.4, seed)
        first, last = clip.phases["wave"]
        lateral = heads_of(clip)[first:last + 1, joint("LeftHand"), 0]
        spectrum = np.abs(np.fft.rfft(lateral - lateral.mean(), n=4096))
        frequency = np.fft.rfftfreq(4096, d=1.0 / clip.fps)[np.argmax(spectrum)]
        assert 2.0 <= frequency <= 3.0


def single_peak(speed):
    """True when the speed curve has one local maximum above a fifth of its peak."""
    peaks = [i for i in range(1, len(speed) - 1) if speed[i] >= speed[i - 1] and speed[i] > speed[i + 1]
             and speed[i] > 0.2 * speed.max()]
    return len(peaks) == 1


def test_stroke_speed_is_bell_shaped():
    rng = np.random.default_rng()
    for arm in skeleton.ARMS:
        side = skeleton.ARM_PREFIX[arm]
        for clip, phase in (
            (point(arm, random_target(rng, arm), 7), "stroke"),
            (point(arm, random_target(rng, arm), 8), "return"),
            (wave(arm, 0.7, 9), "raise"),
            (wave(arm, 0.3, 10), "lower"),
        ):
            first, last = clip.phases[phase]
            path = heads_of(clip)[first:last + 1, joint(side + "Hand")]
            speed = np.linalg.norm(np.diff(path, axis=0), axis=1)
            assert single_peak(speed), (phase, np.round(speed, 4))
            peak = np.argmax(speed) / (len(speed) - 1)
            assert 0.2 < peak < 0.8  # bell, not a ramp
            # Pointing strokes go rest to rest; a wave's first and last swings overlap its raise and lowering.
            overlap = 0.5 if phase in ("raise", "lower") else 0.2
            assert speed[0] < overlap * speed.max() and speed[-1] < overlap * speed.max()


def test_gaze_leads_the_hand_and_the_torso_turns_for_targets_across_the_body():
    target = np.array([-2.0, -2.2, 1.3])  # across the body for the left arm
    clip = point("LEFT", target, 2)
    heads = heads_of(clip)
    rest = heads[0]

    def arrival(values):  # first frame within 10 % of the final change
        change = np.linalg.norm(values - values[0], axis=-1)
        return int(np.argmax(change >= 0.9 * change[clip.phases["hold"][0]]))

    pose = kinematics.pose_matrices(clip.rotvecs)
    eye_axis = pose[:, joint("LeftEye"), :3, 1]
    assert arrival(eye_axis) < arrival(heads[:, joint("LeftHandIndex1")])
    hold = clip.phases["hold"][0]
    gaze = target - 0.5 * (heads[hold, joint("LeftEye")] + heads[hold, joint("RightEye")])
    assert np.degrees(np.arccos(eye_axis[hold] @ gaze / np.linalg.norm(gaze))) < 3.0
    # The chest turns towards the target: the left collar comes forward (-Y).
    assert heads[hold, joint("LeftShoulder"), 1] < rest[joint("LeftShoulder"), 1] - 0.01


def test_clavicle_rises_for_targets_above_the_shoulder():
    def collar_lift(target):
        clip = point("RIGHT", target, 0)
        heads = heads_of(clip)
        return heads[clip.phases["hold"][0], joint("RightArm"), 2] - heads[0, joint("RightArm"), 2]

    assert collar_lift((-0.8, -1.5, 4.0)) > collar_lift((-0.8, -2.5, 1.45)) + 0.02


def test_timing_varies_moderately_between_styles():
    seeds = np.random.default_rng().integers(1 << 30, size=20)
    lengths = [point("LEFT", (-1.6, -2.0, 3.5), seed).frames / gs.FPS for seed in seeds]  # high, across: slowest
    lengths += [wave("RIGHT", 1.0, seed).frames / gs.FPS for seed in seeds]  # biggest: slowest
    assert len(set(lengths)) > 6
    assert 2.5 <= min(lengths) and max(lengths) <= 4.5


def test_synthesis_is_deterministic_in_the_seed():
    a, b = wave("LEFT", 0.3, seed=11), wave("LEFT", 0.3, seed=11)
    for name in gs.ANIMATED_BONES:
        np.testing.assert_array_equal(a.rotvecs[name], b.rotvecs[name])
    assert gs.draw_style(11) == gs.draw_style(11) != gs.draw_style(12)


def test_minimum_jerk_progress_and_keyed_curves():
    s = np.linspace(0, 1, 101)
    mj = minimum_jerk(s)
    assert mj[0] == 0 and mj[-1] == 1 and np.all(np.diff(mj) >= 0)
    np.testing.assert_allclose(mj[50], 0.5)
    curve = gs.keyed_progress(np.linspace(0, 3, 301), [(0, 0), (1, 0), (2, 1.2), (3, 1)])
    assert curve[0] == 0 and np.isclose(curve[200], 1.2) and np.isclose(curve[-1], 1)


def test_blend_follows_a_great_circle_and_reaches_both_ends():
    start = rotvec_to_matrix(np.array([-1.3, 0.0, 0.1]))
    end = rotvec_to_matrix(np.array([0.2, 0.9, -1.2]))
    frames = blend_rotation("LeftArm", start, end, np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(matrix_to_rotvec(frames[[0, 2]]), matrix_to_rotvec(np.stack([start, end])), atol=1e-9)


@pytest.mark.parametrize("spec", [
    gs.GestureSpec("NOD", "LEFT", exaggeration=0.5),
    gs.GestureSpec("WAVE", "MIDDLE", exaggeration=0.5),
    gs.GestureSpec("WAVE", "LEFT", exaggeration=1.5),
    gs.GestureSpec("POINT", "LEFT"),
    gs.GestureSpec("GUIDE", "LEFT", exaggeration=0.5),
    gs.GestureSpec("RAISE_HAND", "RIGHT", target=(0.0, -2.0, 1.0)),
])
def test_unusable_specs_raise_the_domain_error(spec):
    with pytest.raises(RLAnimateError):
        gs.synthesise(spec)


def test_waves_measure_as_waves_and_their_class_mean_does_not():
    """The behaviour metrics on the generator's own waves: 3-5 cycles at 2-3 Hz with the hand up;
    the per-frame mean of several (a still-ish arm, as a regressing agent makes) fails the swing bound."""
    from rlanimate_addon.core import behaviour_metrics as bm

    waves = [spaces.description_joint_positions(kinematics.describe(
        gs.synthesise(gs.GestureSpec("WAVE", "RIGHT", exaggeration=0.5, seed=seed)).action_rotvecs()))
        for seed in range(6)]
    for wave in waves:
        measures = bm.wave_measures(wave, "RIGHT")
        assert 3 <= measures["cycles"] <= 5 and 2.0 <= measures["frequency"] <= 3.0
        assert 0.1 <= measures["swing"] <= 0.3
    length = min(len(w) for w in waves)
    mean = np.mean([bm.resample(w, length) for w in waves], axis=0)
    comparison = bm.compare_wave(mean, bm.resample(waves[0], length), "RIGHT")
    assert not bm.wave_accepted(comparison)
    assert comparison["swing_ratio"] < bm.WAVE_SWING_RATIO[0]
