"""A folder of takes without a manifest as a labelled library (trainer/motion/capture_folder.py): which takes it
holds, the labels from names and motion, the hold-out by take, and the manifest it writes."""
import numpy as np
import pytest

from rlanimate_addon.core import spaces
from tests.trainer.synthetic_library import make_clip
from trainer.motion import capture_folder, manifest


def _label(name, behaviour="WAVE", arm="RIGHT", exaggeration=0.5, **fields):
    return capture_folder.TakeLabel(f"/takes/{name}", behaviour, fields.pop("kind", "intensity"), arm, 90, 30.0,
                                    exaggeration=exaggeration, **fields)


def test_takes_are_found_in_the_folder_and_its_folders_and_withheld_ones_are_left_unopened(tmp_path):
    (tmp_path / "hello").mkdir()
    for name in ("wave_left_001.bvh", "notes.txt", "hello/take_001.FBX", "dataset-2_wave-left-hand_normal_012.bvh",
                 "dataset-2_wave-left-hand_normal_009.bvh"):
        (tmp_path / name).write_text("never opened")
    paths, notes = capture_folder.find_takes(tmp_path)
    assert [p.relative_to(tmp_path).as_posix() for p in paths] == [
        "dataset-2_wave-left-hand_normal_009.bvh", "hello/take_001.FBX", "wave_left_001.bvh"]
    assert notes == ["left out 1 take(s) held out for evaluation elsewhere, unopened: "
                     "dataset-2_wave-left-hand_normal_012.bvh"]


def test_a_share_of_each_behaviour_and_arm_is_held_out_spread_over_its_labels():
    labels = [_label(f"w{k}", exaggeration=k / 9) for k in range(10)]
    labels += [_label(f"l{k}", arm="LEFT", exaggeration=k / 2) for k in range(3)]
    labels += [_label("alone", behaviour="HELLO")]
    capture_folder.hold_out(labels, 0.2)
    held = [label.name for label in labels if label.split == "test"]
    assert held == ["w2", "w7", "l1"], "2 of 10 right waves spread out, 1 of 3 left, none of a group of one"
    for label in labels:
        label.split = "train"
    capture_folder.hold_out(labels, 0.0)
    assert all(label.split == "train" for label in labels)


def test_a_new_intensity_gesture_is_placed_between_its_lowest_and_highest_takes():
    labels = [_label(f"h{k}", behaviour="HELLO", exaggeration=None, elevation=e) for k, e in enumerate((80, 120, 160))]
    labels.append(_label("o", behaviour="OTHER", exaggeration=None, elevation=100.0))
    capture_folder.place_elevations(labels)
    assert [label.exaggeration for label in labels] == [0.0, 0.5, 1.0, 0.5]


def test_the_manifest_reads_back_as_the_labels(tmp_path):
    """What the user edits and passes back: the manifest reader takes every entry as labelled, and the fields for
    the reader alone (tempo, notes) are ignored by it."""
    direction = tuple(np.array([0.2, -0.9, 0.3]) / np.linalg.norm([0.2, -0.9, 0.3]))
    labels = [_label("w.bvh", tempo=1.25, split="test", notes=["a note"]),
              _label("p.bvh", behaviour="POINT", kind="target", arm="LEFT", exaggeration=None, direction=direction)]
    written = capture_folder.manifest(labels, tmp_path)
    entries, problems = manifest.checked_entries(written, tmp_path / "manifest.json", 30.0)
    assert problems == []
    wave, point = entries
    assert (wave.file, wave.behaviour, wave.arm, wave.exaggeration, wave.split) == ("/takes/w.bvh", "WAVE", "RIGHT",
                                                                                    0.5, "test")
    assert (point.behaviour, point.kind, point.arm, point.split) == ("POINT", "target", "LEFT", "train")
    np.testing.assert_allclose(point.direction, direction, atol=1e-5)
    np.testing.assert_allclose(spaces.pointing_direction("LEFT", point.target), direction, atol=1e-4)
    assert written["clips"][0]["tempo_hz"] == 1.25 and written["clips"][0]["notes"] == ["a note"]


def test_a_wave_too_short_to_read_its_swing_is_held_out_and_said(tmp_path):
    short = make_clip("short", "WAVE", "LEFT", 0.6, 20, 2.0)
    label = capture_folder.label_take(tmp_path / "wave_left_009.bvh", short)
    assert (label.behaviour, label.arm, label.tempo, label.split) == ("WAVE", "LEFT", None, "test")
    assert "too short" in label.notes[0] and "never trained on" in label.notes[0]
    long = capture_folder.label_take(tmp_path / "wave_right_001.bvh", make_clip("long", "WAVE", "LEFT", 0.6, 150, 2.0))
    assert long.tempo == pytest.approx(2.0, rel=0.05) and long.split == "train"
    assert long.notes == ["the name says right arm, the motion moves the left one more"]
    hello = capture_folder.label_take(tmp_path / "hello" / "take_1.bvh", make_clip("h", "WAVE", "RIGHT", 0.6, 90))
    assert (hello.behaviour, hello.kind, hello.arm) == ("HELLO", "intensity", "RIGHT") and hello.elevation > 0
