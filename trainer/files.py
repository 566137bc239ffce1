"""The trainer's one way to write a file: to a temporary file beside it, then moved into place.

A reader never sees half a file, and a run killed mid-write leaves the previous file intact.
"""
import os
import shutil
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_open(path, mode="wb"):
    """Open a temporary file beside `path` for writing; on success it is flushed, synced and moved onto
    `path`, on an error it is removed and `path` is untouched."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(temporary, mode) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


def atomic_write_text(path, text):
    with atomic_open(path, "w") as handle:
        handle.write(text)


def atomic_copy(source, target):
    with atomic_open(target) as handle, open(source, "rb") as original:
        shutil.copyfileobj(original, handle)
