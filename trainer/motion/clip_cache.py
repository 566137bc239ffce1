"""The import cache: imported clips kept as .npz files keyed by the source file's SHA-256, so training does
not re-import every FBX file each run. Numpy only; trainer/blender_io/clip_import.py fills it."""
import hashlib

import numpy as np

from rlanimate_addon.core import skeleton
from trainer.files import atomic_open
from trainer.motion.clip import MotionClip

CACHE_DIR_NAME = ".import_cache"
#: Bump when the import or the canonicalisation changes what a file turns into: old cache entries are ignored.
IMPORT_VERSION = 1


def file_hash(path):
    """Cache key of a clip file: its bytes, the importer version and the canonical skeleton it is
    retargeted onto (a clip's local rotations are relative to the skeleton's rest frames)."""
    digest = hashlib.sha256(f"v{IMPORT_VERSION}:{skeleton.BONES!r}:".encode())
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()[:32]


def load_cached(cache_file, path):
    with np.load(cache_file, allow_pickle=False) as data:
        finger_names = [str(n) for n in data["finger_names"]]
        fingers = {name: data["fingers"][:, i] for i, name in enumerate(finger_names)}
        return MotionClip(name=path.stem, source=str(path), fps=float(data["fps"]),
                          rotvecs=data["rotvecs"], fingers=fingers)


def save_cached(cache_file, clip):
    names = sorted(clip.fingers)
    fingers = np.stack([clip.fingers[n] for n in names], axis=1) if names else np.zeros((clip.frames, 0, 3))
    with atomic_open(cache_file) as handle:
        np.savez(handle, rotvecs=clip.rotvecs, fps=clip.fps, fingers=fingers, finger_names=np.array(names, dtype=str))
