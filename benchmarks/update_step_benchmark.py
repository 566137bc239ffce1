"""CPU cost of an epoch of the default training (Algorithm 1's rollouts and update steps), against a revision.

Run: `nice -n 10 python benchmarks/update_step_benchmark.py [--against REV]`.

Each tree, this checkout and with `--against` the revision REV (unpacked by `git archive` into a temporary
folder), runs in worker processes of its own pinned to one CPU core. A worker imports the trainer of its
tree, loads the sample library (this checkout's clips and import cache, Blender FK), builds the default
preset's trainer for every behaviour (the four of `python trainer/train.py`, seed 2), collects WARM_EPOCHS
epochs of rollouts into its buffer (the collection of an epoch is timed), then times ROUNDS rounds of STEPS
update steps on that buffer: the tree's own chunk count, losses, backward and optimiser. Workers of the two
trees take turns, TURNS each, so both see the same load. The section gives each tree's step (median of its
rounds, and the least), its T update steps an epoch, an epoch's cost (T steps and one collection) and the
default run's 100 epochs at that rate, in CPU minutes; the whole run adds the clip import, the evaluations
and the checkpoints (docs/TRAINING.md, "How long training takes"). It replaces the "Update step" section of
docs/BENCHMARKS.md (other sections are kept).
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import tarfile
import tempfile
import time
from datetime import UTC, datetime
from io import BytesIO
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
MANIFEST = REPO_ROOT / "sample_rigs" / "clips" / "manifest.json"
WARM_EPOCHS = 10
ROUNDS = 5
STEPS = 10
TURNS = 2
RUN_EPOCHS = 100
COMMAND = "nice -n 10 python benchmarks/update_step_benchmark.py --against 58ac990"
HEADING = "## Update step"


def worker(tree: str) -> dict:
    """Time the tree's collection and update steps (run in a process of its own, importing the tree's trainer)."""
    sys.path.insert(0, tree)
    import numpy as np
    import torch

    from trainer.agent.algorithm import Trainer, gradient_step
    from trainer.agent.config import load_preset
    from trainer.agent.models import RLAnimateAgent
    from trainer.blender_io.clip_session import LibrarySession
    from trainer.motion.clip import training_space

    torch.set_num_threads(1)
    session = LibrarySession(str(MANIFEST))
    agent_config, config = load_preset("default")
    torch.manual_seed(2)
    agent = RLAnimateAgent(agent_config, "rlanimate", training_space(session.train_clips, "all"))
    trainer = Trainer(agent, session.env, session.train_clips, config, "all", 2, references=session.references,
                      epochs=RUN_EPOCHS)
    collect = []
    for _ in range(WARM_EPOCHS):
        start = time.process_time()
        trainer.collect()
        collect.append(time.process_time() - start)
    agent.train()
    rng = np.random.default_rng(0)

    def step():  # Trainer.update's loop body
        batch = trainer.buffer.sample_chunks(trainer.chunk_count, config.chunk_length, rng,
                                             config.random_target_weight, config.last_frame_share)
        gradient_step(agent, trainer.optimizer, batch, config, trainer.bounds)

    for _ in range(STEPS):  # warm-up
        step()
    rounds = []
    for _ in range(ROUNDS):
        start = time.process_time()
        for _ in range(STEPS):
            step()
        rounds.append((time.process_time() - start) / STEPS)
    return {"rounds": rounds, "collect": collect, "chunks": trainer.chunk_count,
            "update_steps": getattr(trainer, "update_steps", config.update_steps)}


def run_worker(tree: Path) -> dict:
    """worker(tree) in a fresh process pinned to one core; its result."""
    code = (f"import os, sys, json; os.sched_setaffinity(0, {{min(os.sched_getaffinity(0))}}); "
            f"sys.path.insert(0, {str(Path(__file__).parent)!r}); import update_step_benchmark as b; "
            f"print('RESULT ' + json.dumps(b.worker({str(tree)!r})))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tree, check=False)
    lines = [line for line in done.stdout.splitlines() if line.startswith("RESULT ")]
    if done.returncode or not lines:
        raise SystemExit(f"The worker for {tree} failed:\n{done.stderr[-3000:]}")
    return json.loads(lines[-1][len("RESULT "):])


def unpack(revision: str, folder: Path) -> Path:
    """The tree of `revision` of this repository, unpacked into `folder`."""
    archive = subprocess.run(["git", "archive", revision], cwd=REPO_ROOT, capture_output=True, check=True).stdout
    with tarfile.open(fileobj=BytesIO(archive)) as tar:
        tar.extractall(folder, filter="data")
    return folder


def summary(results: list[dict]) -> dict:
    """One tree's figures from its workers' results."""
    import numpy as np
    rounds = np.concatenate([r["rounds"] for r in results])
    step, collect = float(np.median(rounds)), float(np.median(np.concatenate([r["collect"] for r in results])))
    steps = results[0]["update_steps"]
    epoch = steps * step + collect
    return {"step_ms": step * 1e3, "least_ms": float(rounds.min()) * 1e3, "update_steps": steps,
            "chunks": results[0]["chunks"], "collect_s": collect, "epoch_s": epoch,
            "run_minutes": RUN_EPOCHS * epoch / 60.0}


def section(figures: dict, load: float) -> str:
    """The markdown section for docs/BENCHMARKS.md; figures: {label: summary}."""
    rows = [f"| {label} | {f['update_steps']} x {f['chunks']} | {f['step_ms']:.1f} ({f['least_ms']:.1f}) | "
            f"{f['collect_s']:.2f} | {f['epoch_s']:.2f} | {f['run_minutes']:.1f} |" for label, f in figures.items()]
    lines = [HEADING, "",
             "CPU time of the default training's epoch, measured on its own buffer: the sample library's four "
             f"behaviours, seed 2, after {WARM_EPOCHS} epochs of rollouts (Blender FK); each tree in worker "
             f"processes pinned to one core, taking turns ({TURNS} each), {ROUNDS} rounds of {STEPS} update steps "
             "after a warm-up. An update step: sample the chunks, the losses, backward, gradient clip, Adam. An "
             "epoch: T steps and one collection of rollouts.", "",
             f"Regenerate: `{COMMAND}`", "",
             f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs (load average "
             f"{load:.1f} at start), Python {platform.python_version()}. "
             f"Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.", "",
             "| tree | T steps x C chunks | step, median (least) (ms) | collection (s) | epoch (s) | "
             f"{RUN_EPOCHS} epochs (CPU min) |",
             "|---|---:|---:|---:|---:|---:|", *rows]
    if len(figures) == 2:
        (_, before), (_, after) = figures.items()
        lines += ["", f"An update step takes {after['step_ms'] / before['step_ms']:.2f}x the reference tree's time, "
                      f"an epoch {after['epoch_s'] / before['epoch_s']:.2f}x."]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", help="a revision to compare with (its tree is unpacked with git archive)")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    trees = {"this checkout": REPO_ROOT}
    with tempfile.TemporaryDirectory() as folder:
        if args.against:
            trees = {f"{args.against} (before)": unpack(args.against, Path(folder)), **trees}
        results: dict[str, list[dict]] = {label: [] for label in trees}
        for _ in range(TURNS):
            for label, tree in trees.items():
                results[label].append(run_worker(tree))
    text = section({label: summary(r) for label, r in results.items()}, load)
    print(text)
    sys.path.insert(0, str(Path(__file__).parent))
    import report  # benchmarks/report.py
    report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
