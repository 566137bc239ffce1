"""Per-frame cost of the numpy agent runtime (rlanimate_addon/core/runtime.py), on one CPU core.

Run: `nice -n 10 python benchmarks/runtime_benchmark.py`. It pins itself to one core, times
`GestureAgent.rollout` (deterministic, and with a variation seed) on the shipped default agent and on
default-size agents of the other variants, for gestures of 0.4x, 1x and 1.5x the default length,
and the torch agent's rollout for reference. A frame's cost is the whole rollout's CPU time (precompute
included) over its frames, the least of REPEATS interleaved rounds. It prints a markdown section
and replaces the "Numpy runtime" section of docs/BENCHMARKS.md with it (other sections are kept).
"""
import os
import platform
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})

REPO_ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO_ROOT))

import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)
import torch  # noqa: E402

from rlanimate_addon.core import spaces  # noqa: E402
from rlanimate_addon.core.runtime import load_agent  # noqa: E402
from trainer.agent.agent_export import export_agent  # noqa: E402
from trainer.agent.config import load_preset  # noqa: E402
from trainer.agent.models import VARIANTS, RLAnimateAgent  # noqa: E402

DEFAULT_AGENT = REPO_ROOT / "rlanimate_addon" / "agents" / "default.npz"
LENGTH_SCALES = (0.4, 1.0, 1.5)
REPEATS = 30
BUDGET_US = 100.0
COMMAND = "nice -n 10 python benchmarks/runtime_benchmark.py"
HEADING = "## Numpy runtime"
LOAD_AT_START = os.getloadavg()[0]


def least_cpu_seconds(runs):
    """Least CPU time of each of `runs` (callables) over REPEATS rounds, interleaved so that a burst
    of other jobs' load hits one round of every run rather than every round of one. CPU time, not
    wall time: on the shared machine a wall clock also counts the time other jobs hold the core."""
    best = [float("inf")] * len(runs)
    for _ in range(REPEATS):
        for k, run in enumerate(runs):
            start = time.process_time()
            run()
            best[k] = min(best[k], time.process_time() - start)
    return best


def agents(folder):
    """(label, numpy GestureAgent, torch agent or None) to time: the shipped agent, then each variant."""
    yield "shipped default.npz", load_agent(DEFAULT_AGENT), None
    agent_config, _ = load_preset("default")
    for variant in VARIANTS:
        torch.manual_seed(0)
        agent = RLAnimateAgent(agent_config, variant)
        path = Path(folder) / f"{variant}.npz"
        export_agent(agent, path)
        yield f"default-size {variant}", load_agent(path), agent


def measure():
    """Rows of (label, frames, numpy us/frame, seeded numpy us/frame, torch us/frame or None)."""
    torch.set_num_threads(1)
    cases, runs = [], []
    with tempfile.TemporaryDirectory() as folder:
        for label, runtime, torch_agent in agents(folder):
            average = int(round(runtime.average_frames["POINT"]))
            for scale in LENGTH_SCALES:
                frames = max(2, int(round(scale * average)))
                objectives = spaces.PAPER_SPACE.make_objective("POINT", "RIGHT", [-0.3, -0.9, 0.2], frames)
                cases.append((label, frames, torch_agent is not None))
                runs.append(lambda r=runtime, o=objectives: r.rollout(o))
                runs.append(lambda r=runtime, o=objectives: r.rollout(o, seed=1))
                if torch_agent is not None:
                    batch = torch.as_tensor(objectives, dtype=torch.float32)[None]
                    runs.append(lambda a=torch_agent, b=batch: a.rollout(b))
        seconds = iter(least_cpu_seconds(runs))
    rows = []
    for label, frames, has_torch in cases:
        numpy_us, seeded_us = (next(seconds) / frames * 1e6 for _ in range(2))
        torch_us = next(seconds) / frames * 1e6 if has_torch else None
        rows.append((label, frames, numpy_us, seeded_us, torch_us))
    return rows


def section(rows):
    """The markdown section for docs/BENCHMARKS.md."""
    worst = max(max(r[2], r[3]) for r in rows)
    lines = [
        HEADING, "",
        "Cost per frame of the extension's numpy agent runtime (`GestureAgent.rollout`): a whole rollout",
        "(portrayal, task state and per-frame behaviour loop) divided by its frames, least CPU time of "
        f"{REPEATS} interleaved rounds, one sequence per call, pinned to one CPU core; the torch agent's own",
        "rollout for reference.", "",
        f"Regenerate: `{COMMAND}`", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs (load average "
        f"{LOAD_AT_START:.1f} at start), Python {platform.python_version()}, numpy {np.__version__}, torch "
        f"{torch.__version__}. Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.", "",
        "| agent | frames | numpy us/frame | numpy, seeded us/frame | torch us/frame |",
        "|---|---:|---:|---:|---:|",
    ]
    for label, frames, numpy_us, seeded_us, torch_us in rows:
        torch_text = "-" if torch_us is None else f"{torch_us:.1f}"
        lines.append(f"| {label} | {frames} | {numpy_us:.1f} | {seeded_us:.1f} | {torch_text} |")
    lines += ["", f"Slowest: {worst:.1f} us per frame against a budget of {BUDGET_US:.0f} us "
                  f"({'within' if worst <= BUDGET_US else 'OVER'} budget)."]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    table = section(measure())
    print(table)
    report.write_section(HEADING, table)
