"""CPU cost of one training update step (Algorithm 1, step 3) of the default preset, on one CPU core.

Run: `nice -n 10 python benchmarks/update_step_benchmark.py`. It pins itself to one core and times
`Trainer.update`'s inner step (sample C chunks of L frames, the losses, backward, gradient clip, Adam)
on a default-size agent and a buffer of synthetic episodes mixed like the default run's (no Blender
needed: the step's cost depends on the mix of arms, pointing holds and waves, not on the numbers).
Rounds of STEPS steps are timed in CPU time; the section gives the median and least step, and what
the run's updates cost at that rate, against the 15-minute budget for the whole default training.
It replaces the "Update step" section of docs/BENCHMARKS.md (other sections are kept).
"""
import os
import platform
import sys
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

from rlanimate_addon.core import skeleton, spaces  # noqa: E402
from trainer.agent.algorithm import gradient_step  # noqa: E402
from trainer.agent.buffer import EpisodeBuffer  # noqa: E402
from trainer.agent.config import load_preset  # noqa: E402
from trainer.agent.models import RLAnimateAgent  # noqa: E402

ROUNDS = 15
STEPS = 10
EPISODES = 60  # about the buffer's size a third of the way through the default run
EPISODE_FRAMES = (105, 130)
BUDGET_MINUTES = 15.0
COMMAND = "nice -n 10 python benchmarks/update_step_benchmark.py"
HEADING = "## Update step"
LOAD_AT_START = os.getloadavg()[0]


def synthetic_buffer(rng):
    """EPISODES episodes of random frames with the buffer's fields, composed as the default run's buffer
    is at its end (its checkpoint: 300 random-target points, 100 pointing clips, 100 wave clips, each arm
    half of each): in every five episodes three random-target points and one pointing clip, which hold
    their point over 28% of their frames, and one wave clip; the arm alternates. The step's forward
    kinematics runs on each arm's frames of the pointing holds and of the waves, so its cost depends on
    this mix, not on the numbers."""
    buffer = EpisodeBuffer()
    for k in range(EPISODES):
        frames = int(rng.integers(*EPISODE_FRAMES))
        kind = ("random target", "random target", "random target", "pointing clip", "wave clip")[k % 5]
        arm = skeleton.ARMS[k % 2]
        if kind == "wave clip":
            objective = spaces.PAPER_SPACE.make_objective("WAVE", arm, rng.random(), frames)
        else:
            objective = spaces.PAPER_SPACE.make_objective("POINT", arm, rng.normal(size=3), frames)
        hold = np.zeros(frames)
        if kind != "wave clip":
            hold[int(0.45 * frames): int(0.73 * frames)] = 1.0
        buffer.add({"objective": objective, "action": rng.random((frames, spaces.ACTION_SIZE)),
                    "description": rng.normal(size=(frames, spaces.DESCRIPTION_SIZE)),
                    "motion": rng.random((frames, spaces.ACTION_SIZE)),
                    "motion_description": rng.normal(size=(frames, spaces.DESCRIPTION_SIZE)),
                    "hold": hold, "imitate": np.full(frames, float(kind != "random target"))})
    return buffer


def measure():
    """(step CPU seconds per round (ROUNDS,), TrainConfig)."""
    torch.set_num_threads(1)
    torch.manual_seed(0)
    rng = np.random.default_rng(0)
    agent_config, config = load_preset("default")
    agent = RLAnimateAgent(agent_config)
    buffer = synthetic_buffer(rng)
    optimizer = torch.optim.Adam(agent.parameters(), lr=config.learning_rate)
    bounds = np.asarray(spaces.DEFAULT_ACTION_BOUNDS)
    agent.train()

    def step():  # Trainer.update's loop body
        batch = buffer.sample_chunks(config.chunk_count, config.chunk_length, rng, config.random_target_weight)
        gradient_step(agent, optimizer, batch, config, bounds)

    for _ in range(STEPS):  # warm-up
        step()
    per_step = []
    for _ in range(ROUNDS):
        start = time.process_time()
        for _ in range(STEPS):
            step()
        per_step.append((time.process_time() - start) / STEPS)
    return np.array(per_step), config


def section(per_step, config):
    """The markdown section for docs/BENCHMARKS.md."""
    steps = config.epochs_both * config.update_steps
    median, least = float(np.median(per_step)), float(per_step.min())
    minutes = steps * median / 60.0
    return "\n".join([
        HEADING, "",
        "CPU time of one update step of the default preset (C = "
        f"{config.chunk_count} chunks of L = {config.chunk_length} frames: sampling, losses, backward, "
        "gradient clip, Adam) on a default-size agent and a buffer of "
        f"{EPISODES} synthetic episodes mixed like the default run's (random-target points, pointing and "
        f"wave clips, both arms), pinned to one CPU core; {ROUNDS} rounds of {STEPS} steps after a "
        "warm-up. The default run makes "
        f"{config.epochs_both} x {config.update_steps} = {steps} of them; collecting an epoch's rollouts "
        "adds about 0.3 s (collect_seconds in a run's metrics.jsonl).", "",
        f"Regenerate: `{COMMAND}`", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs (load average "
        f"{LOAD_AT_START:.1f} at start), Python {platform.python_version()}, torch {torch.__version__}. "
        f"Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.", "",
        "| step, median (ms) | step, least (ms) | slowest round (ms) | the run's updates at the median (CPU min) |",
        "|---:|---:|---:|---:|",
        f"| {median * 1e3:.1f} | {least * 1e3:.1f} | {per_step.max() * 1e3:.1f} | {minutes:.1f} |", "",
        f"The updates alone take {minutes:.1f} of the {BUDGET_MINUTES:.0f} CPU minutes the default "
        f"training may take ({'within' if minutes <= BUDGET_MINUTES else 'OVER'} budget).",
    ]) + "\n"


if __name__ == "__main__":
    text = section(*measure())
    print(text)
    report.write_section(HEADING, text)
