"""Seeded mutations of a clip manifest, and the judge of what loading one gives.

`mutations(manifest, rng)` yields (kind, bytes): a field of an entry set to a value of a wrong type or out
of range, or removed; an entry replaced by a non-object; the top level's fps, clips or whole document
replaced; JSON nested deeply; bytes flipped, cut or prefixed (a BOM, latin-1). `outcome(path, load)` runs
`load(path) -> (clips, problems)` (trainer.blender_io.clip_import.import_clip_directory) and names what
happened: 'refused' (an RLAnimateError naming the manifest), 'skipped' (each bad entry noted, naming the
manifest and the entry), 'accepted', or 'failure: ...' (another exception, a vague note, or an accepted
clip whose labels could not make a finite objective). `small_library` is the library mutated. Used by
tests/trainer/blender_io/test_manifest_fuzz.py and benchmarks/manifest_fuzz_benchmark.py.
"""
import json
import math
import shutil
import traceback

import numpy as np

from rlanimate_addon.core.behaviours import TARGET
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion.clip import library_space
from trainer.paths import DEFAULT_MANIFEST

FIELDS = ("file", "behaviour", "arm", "target", "direction", "exaggeration", "frames", "fps", "split")
KINDS = ("field_value", "field_removed", "entry_value", "top_level", "deep_nesting", "bytes")
ACCEPTED = ("refused", "skipped", "accepted")
LIBRARY_FILES = ("point_left_000.fbx", "point_right_001.fbx", "wave_left_000.fbx", "wave_right_001.fbx")


def small_library(folder):
    """Copy 4 of the sample library's clips into `folder` with a manifest of them (two "train", two "test");
    returns the manifest's dict."""
    sample = json.loads(DEFAULT_MANIFEST.read_text())
    clips = [dict(e, split="test" if k % 2 else "train")
             for k, e in enumerate(e for e in sample["clips"] if e["file"] in LIBRARY_FILES)]
    for entry in clips:
        shutil.copy(DEFAULT_MANIFEST.parent / entry["file"], folder / entry["file"])
    manifest = {"fps": sample["fps"], "rig": "../character.fbx", "clips": clips}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return manifest


def _deep(depth):
    return "[" * depth + "]" * depth


#: Values of the wrong type or out of range for some field (JSON text, so that NaN and Infinity can be written).
WRONG_VALUES = (
    '"abc"', '""', '"fast"', '"thirty"', '"here"', '"big"', '"POINT"', '"WAVE"', '"LEFT"', '"test"', '"train"',
    "null", "true", "false", "0", "-1", "1", "2", "2.5", "30", "1e300", "-1e300", "1e400", "Infinity", "-Infinity",
    "NaN", "-0.0", "100000000000000000000000000000000000000000", "[]", "{}", '{"a": 1}', "[1, 2]", "[1, 2, 3, 4]",
    "[0, 0, 0]", "[NaN, 0, 1]", "[Infinity, 0, 1]", "[1e300, 1e300, 1e300]", '["1", "2", "3"]', "[true, false, true]",
    "[[1], [2], [3]]", '"' + "x" * 5000 + '"', '"../../etc/passwd"', '"\\u0000"', _deep(50), "[0.8, -1.5, 1.6]",
    "[-0.6, -0.5, -0.6]", "0.35",
)


def _text(manifest):
    return json.dumps(manifest, indent=1)


def _with_value(manifest, path, value_text):
    """The manifest's JSON text with the value at `path` (keys and indexes) replaced by raw JSON text."""
    marker = "__FUZZ_VALUE__"
    copy = json.loads(json.dumps(manifest))
    node = copy
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = marker
    return _text(copy).replace(json.dumps(marker), value_text, 1)


def mutations(manifest, rng):
    """Yield (kind, bytes) forever: seeded mutations of `manifest` (a dict with a 'clips' list)."""
    entries = len(manifest["clips"])
    while True:
        kind = KINDS[int(rng.integers(len(KINDS)))]
        entry = int(rng.integers(entries))
        value = WRONG_VALUES[int(rng.integers(len(WRONG_VALUES)))]
        if kind == "field_value":
            field = FIELDS[int(rng.integers(len(FIELDS)))]
            text = _with_value(manifest, ("clips", entry, field), value)
        elif kind == "field_removed":
            copy = json.loads(json.dumps(manifest))
            copy["clips"][entry].pop(FIELDS[int(rng.integers(len(FIELDS)))], None)
            text = _text(copy)
        elif kind == "entry_value":
            text = _with_value(manifest, ("clips", entry), value)
        elif kind == "top_level":
            choice = int(rng.integers(3))
            text = (_with_value(manifest, ("fps",), value) if choice == 0
                    else _with_value(manifest, ("clips",), value) if choice == 1 else value)
        elif kind == "deep_nesting":
            depth = int(rng.choice([900, 5000, 100_000]))
            text = _with_value(manifest, ("clips", entry, FIELDS[int(rng.integers(len(FIELDS)))]), _deep(depth)) \
                if rng.random() < 0.5 else _deep(depth)
        else:
            yield kind, _byte_mutation(_text(manifest).encode(), rng)
            continue
        yield kind, text.encode()


def _byte_mutation(data, rng):
    choice = int(rng.integers(4))
    if choice == 0:  # flip bytes
        data = bytearray(data)
        for _ in range(int(rng.integers(1, 4))):
            data[int(rng.integers(len(data)))] = int(rng.integers(256))
        return bytes(data)
    if choice == 1:  # cut short
        return data[:int(rng.integers(len(data)))]
    if choice == 2:  # a UTF-8 BOM, as Windows editors save: still the same manifest
        return b"\xef\xbb\xbf" + data
    return data.decode().replace('"', '"\xe9', 1).encode("latin-1")  # latin-1, not UTF-8


def outcome(path, load):
    """'refused', 'skipped', 'accepted' or 'failure: ...' for loading the manifest at `path` with `load`."""
    try:
        clips, problems = load(path)
    except RLAnimateError as error:
        return "refused" if str(path) in str(error) else f"failure: the refusal does not name the manifest: {error}"
    except Exception:  # noqa: BLE001 (the fuzz counts every other exception as a failure)
        return "failure: " + traceback.format_exc(limit=-2)
    for problem in problems:  # a note names the manifest's entry, or the clip file that did not import
        if not (f"{path}: entry " in problem or problem.startswith(str(path.parent))):
            return f"failure: a note that names neither the manifest entry nor the clip file: {problem}"
    for clip in clips:
        failure = _label_failure(clip)
        if failure:
            return f"failure: {clip.name}: {failure}"
    return "skipped" if problems else "accepted"


def _label_failure(clip):
    """Why an accepted clip's labels cannot train (None when they can): its objective must be finite."""
    if clip.split not in ("train", "test"):
        return f"split {clip.split!r}"
    if clip.behaviour_kind == TARGET:  # a mutated name is another behaviour, of the kind its fields give
        direction = np.asarray(clip.attributes, dtype=np.float64)
        if direction.shape != (3,) or not math.isclose(float(np.linalg.norm(direction)), 1.0, rel_tol=1e-6):
            return f"pointing direction {clip.attributes!r}"
    elif not (isinstance(clip.attributes, float) and 0.0 <= clip.attributes <= 1.0):
        return f"exaggeration {clip.attributes!r}"
    objective = library_space([clip]).make_objective(clip.behaviour, clip.arm, clip.attributes, clip.frames)
    return None if np.all(np.isfinite(objective)) else "an objective that is not finite"
