"""Clip manifests (sample_rigs/clips/manifest.json): reading one, and putting an entry's labels on its clip.

    {"fps": 30, "rig": "../character.fbx", "clips": [{"file": "point_left_000.fbx", "behaviour": "POINT",
     "arm": "LEFT", "target": [x, y, z] or null, "direction": [ux, uy, uz] or null,
     "exaggeration": null or e, "frames": F, "fps": 30, "split": "train" or "test"}, ...]}
"""
import json
from pathlib import Path

import numpy as np

from rlanimate_addon.core import behaviours, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError


def manifest_path(clips):
    """A clip library's manifest.json: `clips` itself, or the manifest in the folder `clips`."""
    path = Path(clips)
    return path / "manifest.json" if path.is_dir() else path


def read_manifest(path):
    try:
        manifest = json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError) as error:
        raise RLAnimateError(f"{path}: cannot read the clip manifest ({error}). "
                             "Regenerate it or point to the right file.") from error
    if not isinstance(manifest, dict) or not isinstance(manifest.get("clips"), list):
        raise RLAnimateError(f"{path}: the manifest has no 'clips' list. Regenerate it.")
    return manifest


def labelled(clip, entry, manifest_path):
    """Attach a manifest entry's labels to `clip`; raises RLAnimateError for an unusable entry."""
    behaviour = str(entry.get("behaviour", "")).upper()
    arm = str(entry.get("arm", "")).upper()
    if behaviour not in behaviours.BEHAVIOURS or arm not in skeleton.ARMS:
        raise RLAnimateError(f"{manifest_path}: entry {entry.get('file')!r} has behaviour {behaviour!r} and arm "
                             f"{arm!r}; use POINT or WAVE and LEFT or RIGHT.")
    frames = entry.get("frames")
    if frames is not None and int(frames) != clip.frames:
        raise RLAnimateError(f"{clip.source}: the clip has {clip.frames} frames but the manifest says "
                             f"{frames}. Regenerate the clip library.")
    clip.behaviour, clip.arm, clip.split = behaviour, arm, entry.get("split")
    if behaviour == behaviours.POINT:
        if entry.get("direction") is not None:
            direction = np.asarray(entry["direction"], dtype=np.float64)
            clip.attributes = direction / np.linalg.norm(direction)
        elif entry.get("target") is not None:
            clip.attributes = spaces.pointing_direction(arm, entry["target"])
        else:
            raise RLAnimateError(f"{manifest_path}: point clip {entry.get('file')!r} has neither a target "
                                 "nor a direction. Add one.")
        clip.target = None if entry.get("target") is None else tuple(float(v) for v in entry["target"])
    else:
        if entry.get("exaggeration") is None:
            raise RLAnimateError(f"{manifest_path}: wave clip {entry.get('file')!r} has no exaggeration. Add one.")
        clip.exaggeration = float(entry["exaggeration"])
        clip.attributes = clip.exaggeration
    return clip
