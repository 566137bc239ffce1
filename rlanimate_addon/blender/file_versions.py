"""What a file the user picked holds (an agent, a VRM's bone map), or why it cannot be read, read once per
version of the file (its path, modification time and size): the panel asks on every redraw, and a bad
file is read once, not on each of them."""
import os
from collections.abc import Callable

from ..core.errors import RLAnimateError


def version(path) -> tuple | None:
    """(path, modification time, size) of a file, or None when it cannot be stat'ed."""
    try:
        stat = os.stat(path)
    except (OSError, ValueError):  # ValueError: a NUL in the path
        return None
    return str(path), stat.st_mtime_ns, stat.st_size


class _Failed(str):
    """The message of the RLAnimateError a read raised (kept, not the error: its traceback holds frames)."""


class PerVersion:
    """Values read from files, or the messages of the RLAnimateErrors reading them raised, by file version;
    at most `kept` versions (then forgotten all at once)."""

    def __init__(self, kept: int):
        self._kept = kept
        self._read: dict[tuple, object] = {}

    def known(self, path) -> bool:
        """Whether this version of the file at `path` was read (its value or why it could not be)."""
        return bool(path) and version(path) in self._read

    def read(self, path, load: Callable, read: bool = True):
        """load(path), once per version of the file; a failure raises the same RLAnimateError each time. With
        read=False (in draw()) nothing is read: None for a version not read yet."""
        key = version(path)
        if key not in self._read:
            if not read:
                return None
            if key is None:
                return load(path)  # raises, naming why the file cannot be read
            if len(self._read) >= self._kept:
                self._read.clear()
            try:
                self._read[key] = load(path)
            except RLAnimateError as error:
                self._read[key] = _Failed(error)
        if isinstance(self._read[key], _Failed):
            raise RLAnimateError(str(self._read[key]))
        return self._read[key]
