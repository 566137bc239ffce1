"""Ray, the engine that runs training runs and clip imports side by side: on this machine by default, or
on a cluster that `ray start` made (docs/TRAINING.md, "Many runs, many machines").

`connect()` starts a local Ray with no set-up (`address` None; never a cluster that happens to run here)
or joins a cluster (`"auto"`: the one `ray start` made on this machine; `"HOST:PORT"`; `"ray://HOST:PORT"`:
a remote head through Ray Client). `run_tasks(function, arguments)` runs `function(argument)` for each
argument as a Ray task, one CPU and a fresh worker process each (so each has its own bpy and torch
state, as the processes of a serial run would), and yields (argument, result) as they finish. Every
node needs the repository at the same path: the workers import `trainer` from it. Ray's own logs stay
in its session folder: nothing of it reaches the terminal but errors.
"""
import logging
import os
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from trainer.paths import REPO_ROOT


def connect(address: str | None = None, workers: int | None = None) -> None:
    """Start a local Ray of `workers` CPUs (None: every CPU), or join the cluster at `address`; once per
    process (a second call keeps the first connection)."""
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # no usage reports: nothing goes to the network
    import ray
    if ray.is_initialized():
        return
    options = {"log_to_driver": False, "logging_level": logging.ERROR}
    if address is None:  # the local workers inherit this environment
        os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, (str(REPO_ROOT), os.environ.get("PYTHONPATH"))))
        options.update(num_cpus=workers, include_dashboard=False)
    else:
        options.update(runtime_env={"env_vars": {"PYTHONPATH": str(REPO_ROOT)}})
    ray.init(address=address or "local", **options)  # "local": a new Ray even when `ray start` made one here


def run_tasks(function: Callable[[Any], Any], arguments: Iterable[Any]) -> Iterator[tuple[Any, Any]]:
    """(argument, function(argument)) for each argument, in the order the Ray tasks finish. A failed task
    cancels the others and raises RuntimeError naming its argument, with the task's error as the cause."""
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
            raise RuntimeError(f"The task for {argument} failed: {error}") from error
        yield argument, result
