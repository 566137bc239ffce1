"""Regenerate the paper's Section 4 results: Table 4, Figure 3 and length flexibility.

    nice -n 10 python -m trainer.scripts.experiments [--preset default] [--epoch-scale 1.0] [--jobs 2]

Trains the four variants (RLAnimate and its three ablations) on each column (wave, point, both)
for the paper's 50 / 100 epochs times --epoch-scale, each run by `trainer.scripts.train` in its own
process, --jobs at a time, into runs/experiments/<variant>_<column>/. Runs that already finished are
kept and interrupted ones resume from their checkpoints. Then it writes to docs/results/ (with
--seed N other than 0: runs/experiments_seedN/ and docs/results/seedN/):
    table4.json   {variant: {column: {score, smoothness, episodes, train_seconds}}} (held-out clips)
    table4.md     the same as a table, with the training-clip scores and the run settings
    figure3_seen.png, figure3_unseen.png   score over epochs on seen and unseen clips
    length_flexibility.json/.png           smoothness of the RLAnimate both-agent's held-out gestures
                                           time-scaled 0.3x-1.7x the class average length
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path


import numpy as np
import torch

from rlanimate_addon.core import metrics
from trainer.agent import checkpoint
from trainer.agent.config import load_preset
from trainer.agent.models import VARIANTS, RLAnimateAgent
from trainer.blender_io.clip_session import LibrarySession
from trainer.evaluation import scoring
from trainer.paths import DEFAULT_MANIFEST, REPO_ROOT, RESULTS_DIR
from trainer.reporting import plots
from trainer.scripts.cli import run_main, script_args

COLUMNS = ("wave", "point", "both")
#: The paper's training lengths (Figure 3): 50 epochs for one behaviour, 100 for both.
PAPER_EPOCHS = {"point": 50, "wave": 50, "both": 100}
LENGTH_SCALES = tuple(float(s) for s in np.round(np.arange(0.3, 1.71, 0.1), 2))


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.experiments", description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="default")
    parser.add_argument("--epoch-scale", type=float, default=1.0,
                        help="fraction of the paper's 50 / 100 epochs to train (CPU budget)")
    parser.add_argument("--variants", nargs="+", choices=VARIANTS, default=list(VARIANTS))
    parser.add_argument("--columns", nargs="+", choices=COLUMNS, default=list(COLUMNS))
    parser.add_argument("--clips", default=str(DEFAULT_MANIFEST))
    parser.add_argument("--runs", help="default: runs/experiments, runs/experiments_seed<N> for another seed")
    parser.add_argument("--results", help="default: docs/results, docs/results/seed<N> for another seed")
    parser.add_argument("--eval-every", type=int, default=5)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--jobs", type=int, default=1, help="training runs at a time, one process each")
    return parser


def parse_options(argv=None):
    """The command line, with --runs and --results defaulting to per-seed folders beyond seed 0, so
    that another seed never reuses seed 0's runs or overwrites its results."""
    options = build_parser().parse_args(script_args(argv))
    suffix = "" if options.seed == 0 else f"_seed{options.seed}"
    options.runs = options.runs or str(REPO_ROOT / "runs" / f"experiments{suffix}")
    default_results = RESULTS_DIR if options.seed == 0 else RESULTS_DIR / f"seed{options.seed}"
    options.results = options.results or str(default_results)
    return options


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


def table4_markdown(table, seen, settings):
    lines = ["# Table 4: final score and smoothness imitating held-out clips", "", settings, "",
             "| variant | wave score | wave smooth. | point score | point smooth. | both score | both smooth. |",
             "|---|---|---|---|---|---|---|"]
    for variant, columns in table.items():
        cells = []
        for column in COLUMNS:
            entry = columns.get(column)
            cells += [f"{entry['score']:.2f}", f"{entry['smoothness']:.2f}"] if entry else ["-", "-"]
        lines.append(f"| {plots.VARIANT_LABELS[variant]} | " + " | ".join(cells) + " |")
    lines += ["", "Sample episodes, training time (wall clock and CPU seconds, on a machine shared with other "
              "jobs) and score on 10 training (seen) clips per run:", "",
              "| variant | column | episodes | wall s | CPU s | seen score | seen smooth. |", "|---|---|---|---|---|---|---|"]
    for variant, columns in table.items():
        for column, entry in columns.items():
            lines.append(f"| {plots.VARIANT_LABELS[variant]} | {column} | {entry['episodes']} | "
                         f"{entry['train_seconds']:.0f} | {seen[variant][column]['cpu_seconds']:.0f} | "
                         f"{seen[variant][column]['score']:.2f} | {seen[variant][column]['smoothness']:.2f} |")
    return "\n".join(lines) + "\n"


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


def main(argv=None):
    options = parse_options(argv)
    torch.set_num_threads(1)
    results = Path(options.results)
    results.mkdir(parents=True, exist_ok=True)
    train_all(options)
    table = write_table_and_figures(options, results)
    for variant, columns in table.items():
        for column, entry in columns.items():
            print(f"{variant:16s} {column:5s} held-out score {entry['score']:6.2f} smoothness "
                  f"{entry['smoothness']:6.2f} episodes {entry['episodes']} {entry['train_seconds']:.0f}s")
    flexibility = write_length_flexibility(options, results)
    if flexibility:
        print("length flexibility:", json.dumps(flexibility))
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
