"""Ray, the engine that runs training runs side by side: on this machine by default, or
on a cluster that `ray start` made (docs/TRAINING.md, "Many runs, many machines").

`connect()` starts a local Ray with no set-up (`address` None; never a cluster that happens to run here)
or joins a cluster (`"auto"`: the one `ray start` made on this machine; `"HOST:PORT"`; `"ray://HOST:PORT"`:
a remote head through Ray Client). `run_tasks(function, arguments)` runs `function(argument)` for each
argument as a Ray task, one CPU and a fresh worker process each (so each has its own bpy and torch
state, as the processes of a serial run would), and yields (argument, result) as they finish. Every
node needs the repository at the same path: the workers import `trainer` from it. Ray's own logs stay
in its session folder: nothing of it reaches the terminal but errors. A task that fails with an
RLAnimateError (a refusal: a damaged checkpoint, a bad setting) raises it as one line naming its argument.

A local Ray ends with the process that started it, however that process ends: on Linux Ray ties its head
processes to it, but its dashboard and runtime-env agents, orphaned by a SIGKILL, wait up to minutes on the
head they lost, so a watchdog process (`_watch`) ends every process the driver started once the driver is
gone (elsewhere Ray's own reaper ends the driver's process group).
"""
import logging
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from rlanimate_addon.core.errors import RLAnimateError
from trainer.paths import REPO_ROOT

#: The watchdog of this process's local Ray: its stdin is a pipe that closes when this process ends.
_watchdog = None


def connect(address: str | None = None, workers: int | None = None) -> None:
    """Start a local Ray of `workers` CPUs (None: every CPU), or join the cluster at `address`; once per
    process (a second call keeps the first connection)."""
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # no usage reports: nothing goes to the network
    import ray
    if ray.is_initialized():
        return
    options: dict[str, Any] = {"log_to_driver": False, "logging_level": logging.ERROR}
    if address is None:  # the local workers inherit this environment
        os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, (str(REPO_ROOT), os.environ.get("PYTHONPATH"))))
        options.update(num_cpus=workers, include_dashboard=False)
    else:
        options.update(runtime_env={"env_vars": {"PYTHONPATH": str(REPO_ROOT)}})
    ray.init(address=address or "local", **options)  # "local": a new Ray even when `ray start` made one here
    if address is None and sys.platform.startswith("linux"):
        _start_watchdog()


def _start_watchdog() -> None:
    """Start `_watch` in a session of its own (a Ctrl-C at the terminal leaves it to clean up), its stdin a
    pipe only this process holds."""
    global _watchdog
    if _watchdog is None or _watchdog.poll() is not None:
        _watchdog = subprocess.Popen([sys.executable, "-c", "from trainer.cluster import _watch; _watch()"],
                                     stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     start_new_session=True, cwd=REPO_ROOT)


def _watch(interval: float = 0.5, grace: float = 1.0) -> None:
    """The watchdog's process: note the processes descended from its parent (the driver) every `interval`
    seconds; once the parent is gone (the stdin pipe reads end-of-file), SIGTERM those still running,
    then SIGKILL any left after `grace` seconds."""
    driver, started = os.getppid(), {}
    gone = threading.Event()

    def wait_for_the_driver() -> None:
        sys.stdin.buffer.read()
        gone.set()

    threading.Thread(target=wait_for_the_driver, daemon=True).start()
    while not gone.wait(interval):
        started.update(process_tree(driver))
    started.pop(os.getpid(), None)
    for sent in (signal.SIGTERM, signal.SIGKILL):
        running = [pid for pid, start in started.items() if start_time(pid) == start]
        for pid in running:
            try:
                os.kill(pid, sent)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + grace
        while running and time.monotonic() < deadline:
            running = [pid for pid in running if start_time(pid) == started[pid]]
            time.sleep(0.05)


def process_tree(root: int) -> dict[int, int]:
    """{pid: start time} of the running processes descended from `root` (Linux /proc), `root` not among them."""
    children: dict[int, list[int]] = {}
    starts: dict[int, int] = {}
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            fields = _stat_fields(int(entry.name))
            if fields is not None and fields[0] != "Z":
                children.setdefault(int(fields[1]), []).append(int(entry.name))
                starts[int(entry.name)] = int(fields[19])
    tree: dict[int, int] = {}
    stack = list(children.get(root, []))
    while stack:
        pid = stack.pop()
        tree[pid] = starts[pid]
        stack.extend(children.get(pid, []))
    return tree


def start_time(pid: int) -> int | None:
    """When the running process `pid` started (clock ticks after boot); None when no process of that id runs."""
    fields = _stat_fields(pid)
    return None if fields is None or fields[0] == "Z" else int(fields[19])


def _stat_fields(pid: int) -> list[str] | None:
    """/proc/PID/stat after the command name: state, ppid, ...; None when the process is gone."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None


def run_tasks(function: Callable[[Any], Any], arguments: Iterable[Any],
              name: Callable[[Any], str] = str) -> Iterator[tuple[Any, Any]]:
    """(argument, function(argument)) for each argument, in the order the Ray tasks finish. A failed task
    cancels the others and raises, naming its argument by `name`: the task's RLAnimateError as one line,
    another error as a RuntimeError with the task's error (and traceback) as the cause."""
    import ray
    remote = ray.remote(num_cpus=1, max_calls=1)(function)
    pending = {remote.remote(argument): argument for argument in arguments}
    while pending:
        [done], _ = ray.wait(list(pending), num_returns=1)
        argument = pending.pop(done)
        try:
            result = ray.get(done)
        except ray.exceptions.RayError as error:
            for reference in pending:
                ray.cancel(reference, force=True)
            cause = getattr(error, "cause", None)
            if isinstance(cause, RLAnimateError):
                raise RLAnimateError(f"{name(argument)}: {cause}") from None
            raise RuntimeError(f"The task for {name(argument)} failed: {error}") from error
        yield argument, result
