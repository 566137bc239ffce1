"""The import cache: imported clips kept as .npz files keyed by the source file's SHA-256, so training does
not re-import every FBX file each run. Numpy only; trainer/blender_io/clip_import.py fills it."""
import hashlib
import lzma
import zipfile
import zlib
from tokenize import TokenError

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


#: What numpy and zipfile raise on a truncated, overwritten or foreign cache file (numpy parses an npy header
#: with Python's tokenizer, hence TokenError and SyntaxError for a damaged one; zipfile raises
#: NotImplementedError for an unknown compression method).
_DAMAGED = (OSError, EOFError, ValueError, KeyError, IndexError, TypeError, SyntaxError, TokenError,
            NotImplementedError, zipfile.BadZipFile, zlib.error, lzma.LZMAError)
_BONE_NAMES = frozenset(bone.name for bone in skeleton.BONES)


def load_cached(cache_file, path):
    """The clip cached in `cache_file` for the clip file `path`; RLAnimateError when the entry is damaged or
    is not what save_cached writes (float64 arrays of the skeleton's shapes, finite, named bones)."""
    try:
        with np.load(cache_file, allow_pickle=False) as data:
            rotvecs, fps, fingers, finger_names = (data[name] for name in ("rotvecs", "fps", "fingers", "finger_names"))
    except _DAMAGED as error:
        raise RLAnimateError(f"The import cache entry {cache_file} is damaged ({type(error).__name__}: {error}).") \
            from error
    frames = len(rotvecs) if rotvecs.ndim else 0
    names = [str(n) for n in finger_names] if finger_names.ndim == 1 and finger_names.dtype.kind == "U" else None
    if not (rotvecs.dtype == fingers.dtype == fps.dtype == np.float64 and fps.shape == () and frames >= 2
            and rotvecs.shape == (frames, len(skeleton.ACTION_JOINTS), 3) and names is not None
            and len(set(names)) == len(names) and _BONE_NAMES.issuperset(names)
            and fingers.shape == (frames, len(names), 3)):
        raise RLAnimateError(f"The import cache entry {cache_file} is damaged (arrays rotvecs {rotvecs.dtype} "
                             f"{rotvecs.shape}, fingers {fingers.dtype} {fingers.shape}, fps {fps.dtype} {fps.shape}, "
                             f"finger_names {finger_names.dtype} {finger_names.shape}: not what the importer writes).")
    if not (np.all(np.isfinite(rotvecs)) and np.all(np.isfinite(fingers)) and np.isfinite(fps) and fps > 0):
        raise RLAnimateError(f"The import cache entry {cache_file} is damaged (values that are not finite, or a "
                             f"frame rate of {float(fps):g}).")
    return MotionClip(name=path.stem, source=str(path), fps=float(fps), rotvecs=rotvecs,
                      fingers={name: fingers[:, i] for i, name in enumerate(names)})


def save_cached(cache_file, clip):
    names = sorted(clip.fingers)
    fingers = np.stack([clip.fingers[n] for n in names], axis=1) if names else np.zeros((clip.frames, 0, 3))
    with atomic_open(cache_file) as handle:
        np.savez(handle, rotvecs=np.asarray(clip.rotvecs, dtype=np.float64), fps=np.float64(clip.fps),
                 fingers=np.asarray(fingers, dtype=np.float64), finger_names=np.array(names, dtype=str))
