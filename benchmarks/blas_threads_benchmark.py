"""The shipped agent's 120-frame rollout with numpy's BLAS on its default threads and on one thread.

Measures `GestureAgent.rollout` as Generate Gesture runs it (one BLAS thread, core/blas_threads.py)
and with that cap lifted, interleaved, on a machine whose cores are busy: `--busy N` starts N
processes that multiply matrices for the length of the run (default: one per core, plus one), and
the load average is recorded. Writes the section "BLAS threads" of docs/BENCHMARKS.md.

Run: `python benchmarks/blas_threads_benchmark.py [--busy N] [--repeats N] [--no-write]`
"""
import argparse
import multiprocessing
import os
import platform
import statistics
import sys
import time
from contextlib import nullcontext
from datetime import UTC, datetime
from pathlib import Path
from unittest import mock

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)
import threadpoolctl  # noqa: E402

from rlanimate_addon.core import blas_threads, gesture, runtime  # noqa: E402

FRAMES = 120
HEADING = "## BLAS threads"
COMMAND = "python benchmarks/blas_threads_benchmark.py"


def busy_work(stop):
    """Another program's load: matrix products until `stop` is set."""
    a = np.random.default_rng(0).normal(size=(300, 300))
    while not stop.is_set():
        a = np.tanh(a @ a.T / 300.0)


def rollout_times(agent, objectives, capped, repeats):
    """Seconds per 120-frame rollout; `capped` False lifts the one-thread cap for the comparison."""
    lifted = nullcontext() if capped else mock.patch.object(blas_threads, "single_blas_thread", nullcontext)
    times = []
    with lifted:
        for _ in range(repeats):
            start = time.perf_counter()
            agent.rollout(objectives)
            times.append(time.perf_counter() - start)
    return times


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--busy", type=int, default=os.cpu_count() + 1, help="busy processes beside the benchmark")
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    agent = runtime.load_agent(ROOT / "rlanimate_addon" / "agents" / "default.npz")
    objectives = gesture.build_objectives(
        agent.space,
        "POINT",
        "RIGHT",
        FRAMES,
        targets=np.tile([-1.2, -2.5, 1.7], (FRAMES, 1)),
        rest_heads=gesture.canonical_rig().rest_heads,
    )
    agent.rollout(objectives)
    blas = [i for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]
    stop = multiprocessing.Event()
    workers = [multiprocessing.Process(target=busy_work, args=(stop,), daemon=True) for _ in range(args.busy)]
    for worker in workers:
        worker.start()
    time.sleep(2.0)
    capped, uncapped = [], []
    try:
        for _ in range(3):  # interleaved rounds, so both see the same load
            capped += rollout_times(agent, objectives, True, args.repeats)
            uncapped += rollout_times(agent, objectives, False, args.repeats)
        load = os.getloadavg()[0]
    finally:
        stop.set()
        for worker in workers:
            worker.join()

    def row(label, times):
        return (f"| {label} | {1e3 * min(times):.1f} | {1e3 * statistics.median(times):.1f} | "
                f"{1e3 * max(times):.1f} |")

    text = "\n".join([
        HEADING, "",
        f"The shipped agent's {FRAMES}-frame rollout (`GestureAgent.rollout`, Point) with numpy's BLAS capped at one",
        "thread, as Generate Gesture runs it (`core/blas_threads.py`), and with the cap lifted, beside",
        f"{args.busy} busy processes multiplying matrices; {3 * args.repeats} rollouts each, interleaved.", "",
        f"Regenerate: `{COMMAND} --busy {args.busy}`", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores, Python {platform.python_version()}, "
        f"numpy {np.__version__}, BLAS: " + ", ".join(f"{i['internal_api']} {i['version']} ({i['num_threads']} threads)"
                                                      for i in blas) + f". Load average {load:.1f}. "
        f"Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.", "",
        "| BLAS threads | best ms | median ms | worst ms |",
        "|---|---:|---:|---:|",
        row("one (the shipped runtime)", capped),
        row("numpy's default", uncapped),
    ]) + "\n"
    print(text)
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
