"""Clip manifests: every entry is checked before anything is imported. An entry with a field of the wrong type
or out of range is skipped with a note naming the manifest, the entry, the field and the fix; a manifest
that cannot be read, or whose own fps is wrong, is refused naming it. The file is never changed."""
import json

import numpy as np
import pytest

from rlanimate_addon.core import spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion.clip import MotionClip, library_space
from trainer.motion.manifest import checked_entries, labelled, read_manifest

POINT = {"file": "point_left_000.fbx", "behaviour": "POINT", "arm": "LEFT", "target": [0.8, -1.5, 1.6],
         "direction": None, "exaggeration": None, "frames": 40, "fps": 30, "split": "train"}
WAVE = {"file": "wave_right_000.fbx", "behaviour": "WAVE", "arm": "RIGHT", "target": None, "direction": None,
        "exaggeration": 0.35, "frames": 40, "fps": 30, "split": "test"}


def write(tmp_path, clips, fps=30, text=None):
    path = tmp_path / "manifest.json"
    path.write_text(text if text is not None else json.dumps({"fps": fps, "clips": clips}))
    return path


def check(path):
    """(entries, problems) as the importer gets them, and the manifest's bytes before."""
    before = path.read_bytes()
    manifest = read_manifest(path)
    entries, problems = checked_entries(manifest, path, 30.0)
    assert path.read_bytes() == before, "the manifest is never changed"
    return entries, problems


@pytest.mark.parametrize("entry, field, shown, fix", [
    ({**POINT, "frames": "abc"}, "frames", "'abc'", "whole number of at least 2"),
    ({**POINT, "frames": 40.5}, "frames", "40.5", "whole number of at least 2"),
    ({**POINT, "frames": True}, "frames", "true", "whole number of at least 2"),
    ({**POINT, "fps": "fast"}, "fps", "'fast'", "frame rate as a number from 1 to 1000"),
    ({**POINT, "target": "here"}, "target", "'here'", "three finite numbers [x, y, z]"),
    ({**POINT, "target": [1, 2]}, "target", "[1, 2]", "three finite numbers [x, y, z]"),
    ({**POINT, "target": None, "direction": [0, 0, 0]}, "direction", "[0, 0, 0]", "not zero"),
    ({**POINT, "target": None, "direction": [float("nan"), 0, 1]}, "direction", "[nan, 0, 1]",
     "three finite numbers"),
    ({**POINT, "target": [float("inf"), 0, 1]}, "target", "[inf, 0, 1]", "three finite numbers"),
    ({**WAVE, "exaggeration": "big"}, "exaggeration", "'big'", "a number from 0 to 1"),
    ({**WAVE, "exaggeration": 1e300}, "exaggeration", "1e+300", "a number from 0 to 1"),
    ({**WAVE, "exaggeration": None}, "exaggeration", "null", "a number from 0 to 1"),
    ({**WAVE, "behaviour": "2 hands"}, "behaviour", "'2 hands'", "a letter followed by letters, digits or underscores"),
    ({**WAVE, "behaviour": "DANCE", "kind": "rhythm"}, "kind", "'rhythm'", "use 'target' or 'intensity'"),
    ({**WAVE, "behaviour": "SHAKE", "does": "point"}, "does", "'point'", "wave, raise (a behaviour of the intensity"),
    ({**WAVE, "arm": 1}, "arm", "1", "use LEFT or RIGHT"),
    ({**WAVE, "split": "validation"}, "split", "'validation'", 'use "train" or "test"'),
    ({**WAVE, "file": 7}, "file", "7", "give the clip's file name"),
])
def test_an_entry_with_a_wrong_field_is_skipped_naming_the_manifest_entry_field_and_fix(tmp_path, entry, field,
                                                                                      shown, fix):
    path = write(tmp_path, [POINT, entry])
    entries, problems = check(path)
    assert [e.file for e in entries] == ["point_left_000.fbx"], "the good entry is kept"
    (problem,) = problems
    name = f" ({entry['file']!r})" if isinstance(entry["file"], str) else ""
    assert problem.startswith(f"{path}: entry 2{name}: field {field!r} is {shown}; ")
    assert fix in problem and problem.endswith("The entry is skipped.")
    assert "NaN" not in problem.replace("nan", "") or "nan" in shown


def test_an_entry_that_is_not_an_object_is_skipped_with_how_to_write_one(tmp_path):
    path = write(tmp_path, ["point_left_000.fbx", POINT])
    entries, (problem,) = check(path)
    assert len(entries) == 1 and entries[0].number == 2
    assert problem.startswith(f"{path}: entry 1: the entry is 'point_left_000.fbx', not an object; write it as {{")


def test_a_point_without_target_or_direction_is_skipped(tmp_path):
    entries, (problem,) = check(write(tmp_path, [{**POINT, "target": None}]))
    assert entries == [] and "a point clip (a target behaviour) needs a 'target' [x, y, z] or a 'direction'" in problem


@pytest.mark.parametrize("text, reason", [
    ('{"fps": "thirty", "clips": []}', "the manifest's field 'fps' is 'thirty'; give the clips' frame rate"),
    ('{"fps": Infinity, "clips": []}', "the manifest's field 'fps' is inf; give"),
    ("[" * 100_000 + "]" * 100_000, "its JSON is nested too deeply"),
    ('{"clips": [}', "cannot read the clip manifest (Expecting value"),
    ('{"clips": "all of them"}', "the manifest has no 'clips' list"),
])
def test_an_unreadable_manifest_is_refused_naming_it(tmp_path, text, reason):
    path = write(tmp_path, None, text=text)
    with pytest.raises(RLAnimateError) as error:
        read_manifest(path)
    assert str(error.value).startswith(f"{path}: ") and reason in str(error.value)


def test_a_manifest_saved_with_a_utf8_bom_is_read(tmp_path):
    path = tmp_path / "manifest.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps({"fps": 30, "clips": [POINT, WAVE]}).encode())
    entries, problems = check(path)
    assert [e.file for e in entries] == [POINT["file"], WAVE["file"]] and problems == []


def test_a_manifest_that_is_not_utf8_is_refused_naming_it(tmp_path):
    path = tmp_path / "manifest.json"
    path.write_bytes(json.dumps({"clips": [POINT]}).replace("point", "p\xe9int").encode("latin-1"))
    with pytest.raises(RLAnimateError, match=r"cannot read the clip manifest \('utf-8' codec can't decode"):
        read_manifest(path)


def test_a_clip_without_a_split_is_a_training_clip_and_entry_fps_defaults_to_the_manifests(tmp_path):
    point = {k: v for k, v in POINT.items() if k not in ("split", "fps")}
    (entry,), _ = checked_entries({"clips": [dict(point, frames=40.0)]}, tmp_path / "manifest.json", 24.0)
    assert entry.split == "train" and entry.fps == 24.0 and entry.frames == 40  # 40.0, as JavaScript writes 40


def test_labels_of_checked_entries_make_finite_objectives(tmp_path):
    direction = {**POINT, "target": None, "direction": [0, -3, 4]}
    entries, problems = check(write(tmp_path, [POINT, WAVE, direction]))
    assert problems == []
    for entry in entries:
        clip = labelled(MotionClip(entry.file, entry.file, 30.0, np.zeros((40, 15, 3))), entry, "manifest.json")
        objective = spaces.PAPER_SPACE.make_objective(clip.behaviour, clip.arm, clip.attributes, clip.frames)
        assert np.all(np.isfinite(objective))
    np.testing.assert_allclose(labelled(MotionClip("d", "d", 30.0, np.zeros((40, 15, 3))), entries[2], "m").attributes,
                               [0, -0.6, 0.8])


def test_a_frame_count_the_clip_does_not_have_names_the_manifest_field(tmp_path):
    (entry,), _ = check(write(tmp_path, [POINT]))
    clip = MotionClip("point_left_000", "clips/point_left_000.fbx", 30.0, np.zeros((37, 15, 3)))
    with pytest.raises(RLAnimateError, match=r"manifest.json: entry 1 \('point_left_000.fbx'\): the manifest's field "
                                             r"'frames' says 40, but the clip clips/point_left_000.fbx has 37 frames\. "
                                             r"Correct 'frames' in the manifest"):
        labelled(clip, entry, tmp_path / "manifest.json")


def test_a_users_behaviour_says_what_it_does_and_its_agent_declares_it(tmp_path):
    aim_at = {**POINT, "behaviour": "AIM_AT", "kind": "target", "does": "point"}
    entries, problems = check(write(tmp_path, [POINT, WAVE, aim_at]))
    assert problems == [] and [e.does for e in entries] == [None, None, "point"]
    clips = [labelled(MotionClip(e.file, e.file, 30.0, np.zeros((40, 15, 3))), e, "m") for e in entries]
    space = library_space(clips)
    assert space.behaviour("AIM_AT").aims and space.behaviour("POINT").aims and space.oscillating() == ("WAVE",)
