"""The paper's Section 4 experiments: one training run per (variant, column), each in its own process,
then Table 4, Figure 3 and length flexibility from the finished runs (`python -m trainer.scripts.experiments`).

`options` is the experiments' command line (trainer/scripts/experiments.py): preset, epoch_scale,
variants, columns, clips, runs, results, eval_every, seed, jobs.
"""
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from rlanimate_addon.core import metrics
from trainer.agent import checkpoint
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent
from trainer.blender_io.clip_session import LibrarySession
from trainer.evaluation import scoring
from trainer.paths import REPO_ROOT
from trainer.reporting import plots
from trainer.reporting.table4 import table4_markdown

COLUMNS = tuple(plots.COLUMN_LABELS)  # wave, point, both
#: The paper's training lengths (Figure 3): 50 epochs for one behaviour, 100 for both.
PAPER_EPOCHS = {"point": 50, "wave": 50, "both": 100}
LENGTH_SCALES = tuple(float(s) for s in np.round(np.arange(0.3, 1.71, 0.1), 2))


def run_folder(options, variant, column):
    return Path(options.runs) / f"{variant}_{column}"


def planned_epochs(options, column):
    return max(1, int(round(PAPER_EPOCHS[column] * options.epoch_scale)))


def is_finished(folder, epochs):
    report = folder / "report.json"
    return report.is_file() and json.loads(report.read_text())["epochs"] == epochs


def train_command(options, variant, column):
    folder = run_folder(options, variant, column)
    command = [sys.executable, "-m", "trainer.scripts.train", "--behaviour", column,
               "--variant", variant, "--preset", options.preset, "--clips", options.clips,
               "--epochs", str(planned_epochs(options, column)), "--seed", str(options.seed),
               "--output", str(folder), "--eval-every", str(options.eval_every), "--quiet"]
    return command + (["--resume"] if (folder / checkpoint.FILENAME).is_file() else [])


def train_all(options):
    """Run every unfinished (variant, column), --jobs processes at a time; raise if one fails."""
    pending = [(m, c) for m in options.variants for c in options.columns
               if not is_finished(run_folder(options, m, c), planned_epochs(options, c))]
    running = []
    while pending or running:
        while pending and len(running) < options.jobs:
            variant, column = pending.pop(0)
            folder = run_folder(options, variant, column)
            folder.mkdir(parents=True, exist_ok=True)
            log = open(folder / "train.log", "w")
            running.append((variant, column, log, subprocess.Popen(
                train_command(options, variant, column), stdout=log, stderr=subprocess.STDOUT, cwd=REPO_ROOT)))
        time.sleep(1.0)
        for entry in list(running):
            variant, column, log, process = entry
            if process.poll() is not None:
                log.close()
                running.remove(entry)
                if process.returncode != 0:
                    raise RuntimeError(f"{variant} {column} failed: see {run_folder(options, variant, column)}/train.log")
                print(f"finished {variant} {column}", flush=True)


def load_run(folder):
    report = json.loads((folder / "report.json").read_text())
    history = [json.loads(line) for line in (folder / "metrics.jsonl").read_text().splitlines()]
    return report, history


def write_table_and_figures(options, results):
    """table4.json/.md and Figure 3 from every finished run of the requested variants and columns."""
    table, seen, histories = {}, {}, {}
    for variant in options.variants:
        for column in options.columns:
            folder = run_folder(options, variant, column)
            if not is_finished(folder, planned_epochs(options, column)):
                continue
            report, history = load_run(folder)
            table.setdefault(variant, {})[column] = {
                "score": report["held_out"]["score"], "smoothness": report["held_out"]["smoothness"],
                "episodes": report["episodes"], "train_seconds": report["train_seconds"]}
            seen.setdefault(variant, {})[column] = {**report["training"], "cpu_seconds": report["train_cpu_seconds"]}
            histories.setdefault(variant, {})[column] = history
    settings = (f"Preset `{options.preset}`, seed {options.seed}, epochs = {options.epoch_scale:g} x the paper's "
                f"(50 for one behaviour, 100 for both; an epoch is one iteration of Algorithm 1). "
                f"Regenerate: `nice -n 10 python -m trainer.scripts.experiments --preset {options.preset} "
                f"--epoch-scale {options.epoch_scale:g}{f' --seed {options.seed}' if options.seed else ''}`.")
    (results / "table4.json").write_text(json.dumps(table, indent=2) + "\n")
    (results / "table4.md").write_text(table4_markdown(table, seen, settings))
    for split in ("seen", "unseen"):
        plots.figure3(histories, results / f"figure3_{split}.png", split)
    return table


def load_trained_agent(folder, preset):
    """The torch agent of a finished run, from its checkpoint."""
    saved = checkpoint.load(folder / checkpoint.FILENAME)
    agent = RLAnimateAgent(load_preset(preset)[0], saved["arguments"]["variant"])
    agent.load_state_dict(saved["trainer"]["agent"])
    return agent


def write_length_flexibility(options, results):
    """Section 4.4 for the RLAnimate both-behaviour agent on the held-out clips."""
    folder = run_folder(options, "rlanimate", "both")
    if not is_finished(folder, planned_epochs(options, "both")):
        return None
    session = LibrarySession(options.clips)
    agent = load_trained_agent(folder, options.preset)
    test = scoring.select_clips(session.test_clips, "both")
    flexibility = scoring.length_flexibility(agent, session.env, test, session.train_clips, LENGTH_SCALES)
    (results / "length_flexibility.json").write_text(json.dumps(flexibility, indent=2) + "\n")
    plots.length_flexibility(flexibility, results / "length_flexibility.png", metrics.ARTEFACT_THRESHOLD)
    return flexibility
