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
    `path` (the folder synced too, so the move survives a power cut), on an error it is removed and `path`
    is untouched. Temporaries of `path` that killed writers left behind are removed first."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(temporary, mode) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
        _sync_folder(path.parent)
    finally:
        temporary.unlink(missing_ok=True)


def remove_stale_temporaries(path):
    """Remove the temporaries of `path` (.NAME.PID.tmp) whose writing process no longer runs; returns them."""
    stale = []
    for temporary in Path(path).parent.glob(f".{Path(path).name}.*.tmp"):
        pid = temporary.name[len(Path(path).name) + 2:-len(".tmp")]
        if pid.isdigit() and not _running(int(pid)):
            temporary.unlink(missing_ok=True)
            stale.append(temporary)
    return stale


def _running(pid):
    if os.name == "nt":  # os.kill(pid, 0) would signal it there: keep every temporary
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _sync_folder(folder):
    try:
        descriptor = os.open(folder, os.O_RDONLY)
    except OSError:  # a platform without directory handles (Windows): the replace is already durable there
        return
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


def atomic_write_text(path, text):
    with atomic_open(path, "w") as handle:
        handle.write(text)


def atomic_copy(source, target):
    with atomic_open(target) as handle, open(source, "rb") as original:
        shutil.copyfileobj(original, handle)
