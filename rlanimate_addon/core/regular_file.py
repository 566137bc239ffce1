"""Opening a file the user named (a bone map, a VRM) only when it is a regular file.

A path field can name a FIFO, /dev/stdin, /dev/zero or a folder: reading one blocks the panel's every
redraw, or never ends. The file is opened without blocking (O_NONBLOCK: opening a FIFO otherwise waits
for a writer) and its type read from the open file itself, so nothing is read from anything else.
"""
import errno
import os
import stat
from typing import BinaryIO

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


class NotRegularFile(OSError):
    """The path names something other than a regular file; `strerror` says what it is."""


def open_regular(path: str | os.PathLike[str]) -> BinaryIO:
    """The regular file at `path`, open for binary reading; NotRegularFile (an OSError) for anything else,
    other OSErrors as `open` raises them."""
    descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    try:
        mode = os.fstat(descriptor).st_mode
        if not stat.S_ISREG(mode):
            kind = next((name for test, name in _KINDS if test(mode)), "something else")
            raise NotRegularFile(errno.EINVAL, f"it is {kind}, not a regular file")
        return os.fdopen(descriptor, "rb")
    except BaseException:
        os.close(descriptor)
        raise
