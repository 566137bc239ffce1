"""Auto-labelling: arm, wave exaggeration and pointing direction from motion alone."""

from types import SimpleNamespace

import numpy as np
import pytest

from rlanimate_addon.core import rotations, skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion import autolabel
from trainer.paths import REALMOCAP_DIR

FPS = 30.0


def _arm_clip(arm, elevations_deg, swings_rad=None, forward_deg=0.0):
    """(F, 15, 3) clip whose `arm` (straight) points `elevations_deg` up from hanging, swinging sideways
    by `swings_rad` and turned `forward_deg` towards the front; the torso and the other arm stay at rest."""
    elevation = np.radians(np.asarray(elevations_deg, dtype=np.float64))
    swing = np.zeros_like(elevation) if swings_rad is None else np.asarray(swings_rad)
    sign = 1.0 if arm == "LEFT" else -1.0
    # World rotation about +Y by (90 deg - elevation) * sign takes the rest arm (+-X) to that elevation,
    # then a turn about +Z brings it forward (-Y). Local = rest^T @ world rotvec (the parents are at rest).
    about_y = np.stack([np.zeros_like(elevation), sign * (np.pi / 2 - elevation + swing),
                        np.zeros_like(elevation)], axis=1)
    rest = skeleton.rest_frame(skeleton.BONE_BY_NAME[skeleton.ARM_PREFIX[arm] + "Arm"])
    about_z = np.zeros_like(about_y)
    about_z[:, 2] = -sign * np.radians(np.broadcast_to(forward_deg, elevation.shape))
    world = rotations.rotvec_to_matrix(about_z) @ rotations.rotvec_to_matrix(about_y)  # (F, 3, 3)
    rotvecs = np.zeros((len(elevation), len(skeleton.ACTION_JOINTS), 3))
    rotvecs[:, skeleton.ACTION_JOINTS.index(skeleton.ARM_PREFIX[arm] + "Arm")] = \
        rotations.matrix_to_rotvec(rest.T @ world @ rest)
    return rotvecs


def _wave(arm, peak_deg, stroke_rad, frames=150, frequency=2.5):
    t = np.arange(frames) / FPS
    raise_share = np.clip(np.minimum(t / 1.0, (t[-1] - t) / 1.0), 0.0, 1.0)  # up in 1 s, down in 1 s
    elevation = 10.0 + (peak_deg - 10.0) * raise_share
    return _arm_clip(arm, elevation, stroke_rad * raise_share * np.sin(2 * np.pi * frequency * t))


@pytest.mark.parametrize("arm", ["LEFT", "RIGHT"])
def test_wave_label_finds_the_arm_and_measures_elevation(arm):
    label = autolabel.label_wave(_wave(arm, 120.0, 0.05), FPS)
    assert label.arm == arm
    assert abs(label.elevation - 120.0) < 5.0  # the strokes (+-3 deg) ride on the raised arm
    assert label.travel[arm] > label.travel["LEFT" if arm == "RIGHT" else "RIGHT"]


def test_exaggeration_grows_with_elevation_and_stroke_and_stays_in_range():
    grid = [[autolabel.label_wave(_wave("RIGHT", peak, stroke), FPS).exaggeration
             for stroke in (0.05, 0.2, 0.5)] for peak in (70.0, 110.0, 170.0)]
    grid = np.array(grid)
    assert np.all(np.diff(grid, axis=0) > 0.05), grid  # higher arm -> more exaggerated
    assert np.all(np.diff(grid, axis=1) > 0.02), grid  # wider strokes -> more exaggerated
    assert grid.min() >= 0.0 and grid.max() <= 1.0
    assert grid[0, 0] < 0.25 and grid[-1, -1] > 0.85


def test_stroke_is_measured_in_arm_lengths():
    small = autolabel.label_wave(_wave("LEFT", 150.0, 0.1), FPS).stroke
    large = autolabel.label_wave(_wave("LEFT", 150.0, 0.3), FPS).stroke
    # A swing of +-a radians moves the straight arm's wrist about 2a arm lengths peak to peak (the
    # half-second detrending window lets a 2.5 Hz wave read up to ~30% larger).
    assert 0.15 < small < 0.3
    assert 2.5 < large / small < 3.5


def test_point_label_recovers_the_held_direction():
    frames = 120
    t = np.arange(frames) / FPS
    share = np.clip(np.minimum(t / 1.0, (t[-1] - t) / 1.0), 0.0, 1.0)
    clip = _arm_clip("RIGHT", 10.0 + 80.0 * share, forward_deg=60.0 * share)
    label = autolabel.label_point(clip)
    assert label.arm == "RIGHT"
    assert 30 <= label.hold_frame <= frames - 30
    expected = np.array([-np.cos(np.radians(60.0)), -np.sin(np.radians(60.0)), 0.0])
    angle = np.degrees(np.arccos(np.clip(label.direction @ expected, -1, 1)))
    assert angle < 5.0, angle


def test_bad_clip_gets_a_clear_error():
    from rlanimate_addon.core.errors import RLAnimateError
    with pytest.raises(RLAnimateError, match="shape"):
        autolabel.label_wave(np.zeros((10, 14, 3)))
    with pytest.raises(RLAnimateError, match="NaN"):
        autolabel.label_wave(np.full((10, 15, 3), np.nan))


@pytest.mark.skipif(not REALMOCAP_DIR.is_dir(), reason=f"real motion capture not found at {REALMOCAP_DIR}")
def test_feminine_waves_label_below_active_waves(tmp_path):
    from trainer.blender_io import clip_import
    labels = {}
    for style in ("feminine", "active"):
        for side in ("left", "right"):
            for take in ("001", "009"):
                path = REALMOCAP_DIR / "wave" / f"dataset-2_wave-{side}-hand_{style}_{take}.bvh"
                clip = clip_import.import_clip(path, cache_dir=tmp_path)
                label = autolabel.label_wave(clip.rotvecs, clip.fps)
                assert label.arm == side.upper(), path.name
                labels.setdefault(style, []).append(label.exaggeration)
    assert max(labels["feminine"]) + 0.3 < min(labels["active"]), labels


def test_label_clip_fills_an_unlabelled_clip():
    from trainer.motion.clip import MotionClip
    clip = autolabel.label_clip(MotionClip("mine", "", FPS, _wave("LEFT", 150.0, 0.2)), "wave")
    assert (clip.behaviour, clip.arm) == ("WAVE", "LEFT")
    assert clip.attributes == clip.exaggeration == clip.label.exaggeration
    from rlanimate_addon.core.errors import RLAnimateError

    with pytest.raises(
        RLAnimateError, match="points and waves only, not DANCE: label the clips of DANCE in a manifest"
    ):
        autolabel.label_clip(clip, "dance")


@pytest.mark.parametrize("path, behaviour", [
    ("capture/wave/dataset-2_wave-left-hand_active_001.bvh", "WAVE"),
    ("clips/raise_hand_right_003.fbx", "RAISE_HAND"),
    ("clips/point_left_000.fbx", "POINT"),
    ("capture/hello/take_001.bvh", "HELLO"),  # no known word: the folder names it
    ("capture/this_way/pointing_ahead.fbx", "THIS_WAY"),  # "pointing" is not the word point
])
def test_a_takes_behaviour_comes_from_a_known_word_of_its_file_name_else_its_folder(path, behaviour):
    assert autolabel.behaviour_from_name(path) == behaviour


def test_a_take_whose_names_name_no_behaviour_is_refused_with_the_fix():
    with pytest.raises(RLAnimateError, match="folder named for it"):
        autolabel.behaviour_from_name("capture/2024-takes/take_001.bvh")


def test_the_arm_a_file_name_gives_is_read_only_when_it_names_one():
    assert autolabel.arm_from_name("dataset-2_wave-left-hand_active_001.bvh") == "LEFT"
    assert autolabel.arm_from_name("wave_right_002.fbx") == "RIGHT"
    assert autolabel.arm_from_name("wave_003.fbx") is None and autolabel.arm_from_name("left_right.fbx") is None


def test_an_intensity_gesture_other_than_a_wave_is_measured_by_how_high_its_arm_goes():
    low, high = _arm_clip("RIGHT", np.linspace(10, 90, 60)), _arm_clip("RIGHT", np.linspace(10, 160, 60))
    (arm, lower), (_, higher) = autolabel.arm_elevation(low), autolabel.arm_elevation(high)
    assert arm == "RIGHT" and lower == pytest.approx(82.0, abs=1.0) and higher == pytest.approx(145.0, abs=1.0)


def test_the_free_arm_is_still_when_only_the_gesturing_arm_moves():
    """free_arm_shift measures the other arm's wrist moved by its own joints: zero for a one-armed wave, the arm's
    sweep for a two-armed one; a behaviour is still-armed when its median clip's shift is at most 5 cm."""
    one = _wave("RIGHT", 150, 0.4)
    two = one + _wave("LEFT", 150, 0.4)  # the left arm waves too (the arms' joints are disjoint)
    assert autolabel.free_arm_shift(one, "RIGHT") == pytest.approx(0.0, abs=1e-9)
    assert autolabel.free_arm_shift(two, "RIGHT") > 0.5
    assert autolabel.free_arm_shift(two, "LEFT") > 0.5
    spine = one.copy()
    spine[:, skeleton.ACTION_JOINTS.index("Spine")] = np.linspace(0, 0.5, len(one))[:, None] * [1.0, 0.0, 0.0]
    assert autolabel.free_arm_shift(spine, "RIGHT") == pytest.approx(0.0, abs=1e-9), "a bow is not the arm's"
    clips = [SimpleNamespace(behaviour="WAVE", arm="RIGHT", rotvecs=r) for r in (one, one, two)]
    clips += [SimpleNamespace(behaviour="CLAP", arm="RIGHT", rotvecs=r) for r in (two, two, one)]
    assert autolabel.still_free_arm(clips) == ["WAVE"]
