"""The import cache: imported clips kept as .npz files keyed by the source file's SHA-256, so training does
not re-import every FBX file each run. Numpy only; trainer/blender_io/clip_import.py fills it."""
import hashlib
import zipfile
import zlib

import numpy as np

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer.files import atomic_open
from trainer.motion.clip import MotionClip

CACHE_DIR_NAME = ".import_cache"
#: Bump when the import or the canonicalisation changes what a file turns into: old cache entries are ignored.
IMPORT_VERSION = 1


def file_hash(path):
    """Cache key of a clip file: its bytes, the importer version and the canonical skeleton it is
    canonicalised onto (a clip's local rotations are relative to the skeleton's rest frames)."""
    digest = hashlib.sha256(f"v{IMPORT_VERSION}:{skeleton.BONES!r}:".encode())
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()[:32]


#: What numpy and zipfile raise on a truncated, overwritten or foreign cache file.
_DAMAGED = (OSError, EOFError, ValueError, KeyError, IndexError, zipfile.BadZipFile, zlib.error)


def load_cached(cache_file, path):
    """The clip cached in `cache_file` for the clip file `path`; RLAnimateError when the entry is damaged."""
    try:
        with np.load(cache_file, allow_pickle=False) as data:
            rotvecs, fps, fingers = data["rotvecs"], float(data["fps"]), data["fingers"]
            finger_names = [str(n) for n in data["finger_names"]]
    except _DAMAGED as error:
        raise RLAnimateError(f"The import cache entry {cache_file} is damaged ({error}).") from error
    frames = len(rotvecs)
    if rotvecs.shape != (frames, len(skeleton.ACTION_JOINTS), 3) or fingers.shape != (frames, len(finger_names), 3) \
            or not (np.all(np.isfinite(rotvecs)) and np.all(np.isfinite(fingers)) and np.isfinite(fps) and fps > 0):
        raise RLAnimateError(f"The import cache entry {cache_file} is damaged (arrays of shapes {rotvecs.shape} "
                             f"and {fingers.shape}, or values that are not finite).")
    return MotionClip(name=path.stem, source=str(path), fps=fps, rotvecs=rotvecs,
                      fingers={name: fingers[:, i] for i, name in enumerate(finger_names)})


def save_cached(cache_file, clip):
    names = sorted(clip.fingers)
    fingers = np.stack([clip.fingers[n] for n in names], axis=1) if names else np.zeros((clip.frames, 0, 3))
    with atomic_open(cache_file) as handle:
        np.savez(handle, rotvecs=clip.rotvecs, fps=clip.fps, fingers=fingers, finger_names=np.array(names, dtype=str))
