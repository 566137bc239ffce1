"""Clip manifests (sample_rigs/clips/manifest.json): reading one, checking every entry before anything is
imported, and putting an entry's labels on its clip.

    {"fps": 30, "rig": "../character.fbx", "clips": [{"file": "point_left_000.fbx", "behaviour": "POINT",
     "arm": "LEFT", "target": [x, y, z] or null, "direction": [ux, uy, uz] or null,
     "exaggeration": null or e, "frames": F, "fps": 30, "split": "train" or "test"}, ...]}

`behaviour` is any name (a letter, then letters, digits or underscores): POINT and WAVE, or a gesture of
the user's own ("beckon"). Its kind (core/behaviours.py) is the entry's "kind" ("target" or "intensity")
when given, POINT's target and WAVE's intensity, else what the entry gives: a target behaviour's clip a
"target" or "direction", an intensity behaviour's an "exaggeration" in [0, 1]. Every clip of one behaviour
has the same kind. A user's behaviour may say what it does ("does": "point", "wave", "present" or "raise",
behaviours.ACTIONS): "point" gets Exact Aim and the pointing hand, "wave" a rhythm and a tempo. `frames`,
`fps` and `split` may be left out (a clip without a split is a training clip). An entry with a field of the
wrong type or out of range is skipped with a note naming the manifest, the entry and the field, as a clip
file that does not import is.
"""
import json
import reprlib
from dataclasses import dataclass
from pathlib import Path, PurePath

import numpy as np

from rlanimate_addon.core import behaviours, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError

#: A manifest larger than this is not a clip list (the sample library's is 40 KB for 188 clips).
MAX_MANIFEST_BYTES = 64 << 20
SPLITS = ("train", "test")
#: Frame rates a clip may declare, and the largest coordinate a target or direction may have (metres).
FPS_RANGE = (1.0, 1000.0)
MAX_COORDINATE = 1e4


@dataclass(frozen=True)
class ManifestEntry:
    """One checked manifest entry: `number` is its place in the manifest's 'clips' list (from 1)."""
    number: int
    file: str
    behaviour: str  # the behaviour's id ("POINT", "WAVE", "BECKON")
    kind: str  # behaviours.TARGET or INTENSITY
    arm: str  # "LEFT" or "RIGHT"
    target: tuple[float, ...] | None = None  # (3,) in the character frame, or None
    direction: tuple[float, ...] | None = None  # (3,) unit vector, or None
    exaggeration: float | None = None
    frames: int | None = None
    fps: float | None = None  # the entry's own, or the manifest's
    split: str = "train"
    does: str | None = None  # behaviours.ACTIONS, or None: the shipped name's

    def describe(self, manifest):
        return f"{manifest}: entry {self.number} ({self.file!r})"


def manifest_path(clips):
    """A clip library's manifest.json: `clips` itself, or the manifest in the folder `clips`."""
    path = Path(clips)
    return path / "manifest.json" if path.is_dir() else path


def read_manifest(path):
    """The manifest at `path` as a dict whose 'clips' is a list and whose 'fps', when given, is a frame
    rate; RLAnimateError naming the file, the problem and the fix otherwise. Its entries are not checked
    here (checked_entries does that)."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(MAX_MANIFEST_BYTES + 1)
        if len(data) > MAX_MANIFEST_BYTES:
            raise ValueError(f"larger than {MAX_MANIFEST_BYTES >> 20} MB")
        manifest = json.loads(data.decode("utf-8-sig"))
    except RecursionError:
        raise RLAnimateError(f"{path}: cannot read the clip manifest (its JSON is nested too deeply). "
                             "Regenerate it or point to the right file.") from None
    except (OSError, ValueError) as error:  # UnicodeDecodeError and JSONDecodeError are ValueErrors
        raise RLAnimateError(f"{path}: cannot read the clip manifest ({error}). "
                             "Regenerate it or point to the right file.") from error
    if not isinstance(manifest, dict) or not isinstance(manifest.get("clips"), list):
        raise RLAnimateError(f"{path}: the manifest has no 'clips' list. Regenerate it.")
    if manifest.get("fps") is not None and _frame_rate_problem(manifest["fps"]):
        raise RLAnimateError(f"{path}: the manifest's field 'fps' is {_shown(manifest['fps'])}; "
                             f"{_frame_rate_problem(manifest['fps'])}. Nothing was imported.")
    return manifest


def checked_entries(manifest, path, default_fps):
    """(entries, problems): a ManifestEntry for every usable entry of `manifest` (read_manifest's), and
    one message per entry skipped, naming the manifest, the entry, the field and the fix."""
    entries, problems, kinds = [], [], {}
    for number, raw in enumerate(manifest["clips"], start=1):
        try:
            entry = _checked(number, raw, default_fps)
            if kinds.setdefault(entry.behaviour, entry.kind) != entry.kind:
                raise _EntryProblem(f"it is a {entry.kind} clip, but the manifest's earlier {entry.behaviour} clips "
                                    f"are {kinds[entry.behaviour]} clips; give every clip of a behaviour the same "
                                    f"kind.")
            entries.append(entry)
        except _EntryProblem as problem:
            name = f" ({raw['file']!r})" if isinstance(raw, dict) and isinstance(raw.get("file"), str) else ""
            problems.append(f"{path}: entry {number}{name}: {problem} The entry is skipped.")
    return entries, problems


class _EntryProblem(Exception):
    """What is wrong with one manifest entry (checked_entries turns it into a skipped entry's note)."""


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxdict, _REPR.maxstring, _REPR.maxother = 2, 4, 3, 40, 40


def _shown(value):
    """A JSON value as a message shows it: short, nesting cut, null and true as JSON writes them, numbers
    as Python does (inf and nan, not JSON's Infinity and NaN)."""
    if value is None or isinstance(value, bool):
        return json.dumps(value)
    return _REPR.repr(value)


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _frame_rate_problem(value):
    if not _is_number(value) or not FPS_RANGE[0] <= value <= FPS_RANGE[1]:
        return f"give the clips' frame rate as a number from {FPS_RANGE[0]:g} to {FPS_RANGE[1]:g}, such as 30"
    return None


def _field(name, value, fix):
    return _EntryProblem(f"field {name!r} is {_shown(value)}; {fix}.")


def _vector(raw, name):
    """A (3,) tuple of finite numbers within MAX_COORDINATE, or None when the field is absent or null."""
    value = raw.get(name)
    if value is None:
        return None
    if not (isinstance(value, list) and len(value) == 3 and all(_is_number(v) and abs(v) <= MAX_COORDINATE
                                                                for v in value)):  # NaN fails the comparison
        raise _field(name, value, f"give three finite numbers [x, y, z] in metres (at most {MAX_COORDINATE:g} "
                                       "in size), or null")
    return tuple(float(v) for v in value)


def _label(raw, name, choices):
    value = raw.get(name)
    if not (isinstance(value, str) and value.upper() in choices):
        raise _field(name, value, f"use {' or '.join(choices)}")
    return value.upper()


def _checked(number, raw, default_fps):
    """The ManifestEntry of the manifest's `number`th entry `raw`; _EntryProblem naming the field otherwise."""
    if not isinstance(raw, dict):
        raise _EntryProblem(f"the entry is {_shown(raw)}, not an object; write it as "
                            '{"file": "clip.fbx", "behaviour": "POINT", "arm": "LEFT", ...} (docs/CLIPS.md).')
    file = raw.get("file")
    if not (isinstance(file, str) and file.strip() and "\0" not in file
            and all(len(part.encode()) <= 255 for part in PurePath(file).parts)):
        raise _field("file", file, "give the clip's file name, relative to the manifest's folder (at most 255 "
                                   "bytes per folder or file name)")
    try:
        behaviour = behaviours.parse(raw.get("behaviour"))
    except RLAnimateError:
        raise _field("behaviour", raw.get("behaviour"), "name the behaviour with a letter followed by letters, "
                                                        "digits or underscores, such as POINT or BECKON") from None
    kind = _kind(raw, behaviour)
    arm = _label(raw, "arm", skeleton.ARMS)
    frames = raw.get("frames")
    if frames is not None:
        whole = isinstance(frames, float) and frames.is_integer() or _is_number(frames) and isinstance(frames, int)
        if not (whole and frames >= 2):
            raise _field("frames", frames, "give the clip's frame count as a whole number of at least 2, or leave it "
                                           "out")
        frames = int(frames)
    fps = raw.get("fps", default_fps)
    if _frame_rate_problem(fps):
        raise _field("fps", fps, _frame_rate_problem(fps))
    split = raw.get("split", "train")
    if split not in SPLITS:
        raise _field("split", split, 'use "train" or "test" (or leave it out for a training clip)')
    target, direction, exaggeration = _vector(raw, "target"), _vector(raw, "direction"), None
    if kind == behaviours.TARGET:
        if direction is not None:
            norm = float(np.linalg.norm(direction))
            if norm < 1e-6:
                raise _field("direction", raw["direction"], "give a direction that is not zero, or null")
            direction = tuple(float(v) for v in np.asarray(direction) / norm)
        elif target is not None:
            try:
                spaces.pointing_direction(arm, target)
            except RLAnimateError:
                raise _field("target", raw["target"], "the target sits on the pointing shoulder: give one "
                                                           "away from the character") from None
        else:
            raise _EntryProblem(f"a {behaviours.key(behaviour)} clip (a target behaviour) needs a 'target' "
                                "[x, y, z] or a 'direction' [ux, uy, uz]; add one.")
    else:
        exaggeration = raw.get("exaggeration")
        if not (_is_number(exaggeration) and 0.0 <= exaggeration <= 1.0):
            raise _field("exaggeration", exaggeration, f"a {behaviours.key(behaviour)} clip (an intensity behaviour) "
                                                       "needs its exaggeration, a number from 0 to 1")
        exaggeration = float(exaggeration)
    does = raw.get("does")
    if does is not None and behaviours.ACTIONS.get(does) != kind:
        raise _field("does", does, f"use one of {', '.join(a for a, k in behaviours.ACTIONS.items() if k == kind)} "
                                   f"(a behaviour of the {kind} kind), or leave it out")
    return ManifestEntry(number, file, behaviour, kind, arm, target, direction, exaggeration, frames, float(fps),
                         split, does)


def _kind(raw, behaviour):
    """The entry's behaviour kind: its "kind", the known kind of POINT and WAVE, else the one its fields give."""
    if raw.get("kind") is not None:
        if raw["kind"] not in behaviours.KINDS:
            raise _field("kind", raw["kind"], f"use {' or '.join(map(repr, behaviours.KINDS))}, or leave it out")
        return raw["kind"]
    if behaviour in behaviours.KNOWN_KINDS:
        return behaviours.KNOWN_KINDS[behaviour]
    targeted = raw.get("target") is not None or raw.get("direction") is not None
    if targeted == (raw.get("exaggeration") is not None):
        raise _EntryProblem(f"the kind of {behaviour} is not given: add \"kind\": \"target\" with a 'target' or "
                            "'direction', or \"kind\": \"intensity\" with an 'exaggeration'.")
    return behaviours.TARGET if targeted else behaviours.INTENSITY


def labelled(clip, entry, manifest_path):
    """Attach a checked ManifestEntry's labels to `clip`; RLAnimateError when the clip's frame count is not
    the one the manifest gives."""
    if entry.frames is not None and entry.frames != clip.frames:
        raise RLAnimateError(f"{entry.describe(manifest_path)}: the manifest's field 'frames' says {entry.frames}, "
                             f"but the clip {clip.source} has {clip.frames} frames. Correct 'frames' in the manifest, "
                             "or regenerate the clip library.")
    clip.behaviour, clip.kind, clip.arm, clip.split = entry.behaviour, entry.kind, entry.arm, entry.split
    clip.does = entry.does
    clip.target = entry.target
    if entry.kind == behaviours.TARGET:
        clip.attributes = np.asarray(entry.direction) if entry.direction is not None \
            else spaces.pointing_direction(entry.arm, entry.target)
    else:
        clip.exaggeration = clip.attributes = entry.exaggeration
    return clip
