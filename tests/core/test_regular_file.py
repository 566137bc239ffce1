"""core.regular_file: a path the user names is read only when it is a regular file; a FIFO, /dev/stdin,
/dev/zero or a folder is refused at once, naming what it is, without blocking."""
import os
import sys
import threading

import pytest

from rlanimate_addon.core import vrm
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.regular_file import NotRegularFile, open_regular

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="FIFOs and /dev are POSIX")


def _within_seconds(call, seconds=5.0):
    """What call() raised, asserting it returned within `seconds` (a blocking read never does)."""
    raised = []

    def run():
        try:
            call()
        except BaseException as error:  # noqa: BLE001  (handed to the test)
            raised.append(error)
    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(seconds)
    assert not worker.is_alive(), f"{call} blocked for {seconds} s"
    return raised[0] if raised else None


@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / "pipe"
    os.mkfifo(path)
    return path


def test_a_regular_file_opens_and_reads(tmp_path):
    path = tmp_path / "map.json"
    path.write_bytes(b"{}")
    with open_regular(path) as handle:
        assert handle.read(10) == b"{}"


@pytest.mark.parametrize("name, kind", [("fifo", "a FIFO (named pipe)"), ("/dev/zero", "a character device"),
                                        ("folder", "a folder")])
def test_anything_else_is_refused_at_once_naming_what_it_is(tmp_path, fifo, name, kind):
    path = {"fifo": fifo, "folder": tmp_path}.get(name, name)
    error = _within_seconds(lambda: open_regular(path))
    assert isinstance(error, NotRegularFile) and error.strerror == f"it is {kind}, not a regular file"


def test_stdin_is_refused_whatever_it_is():
    """/dev/stdin is a terminal, a pipe or /dev/null here: never a regular file to wait on."""
    if os.path.isfile("/dev/stdin"):
        pytest.skip("stdin is redirected from a regular file")
    assert isinstance(_within_seconds(lambda: open_regular("/dev/stdin")), NotRegularFile)


def test_a_vrm_path_naming_a_fifo_is_refused_without_blocking(fifo):
    error = _within_seconds(lambda: vrm.file_roles(str(fifo), ["hips"]))
    assert isinstance(error, RLAnimateError)
    assert str(error) == (f"Cannot read the VRM file {fifo} (it is a FIFO (named pipe), not a regular file): pick the "
                          "character's .vrm file.")
