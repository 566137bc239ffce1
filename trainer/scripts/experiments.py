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
import sys
from pathlib import Path

import torch

from trainer.agent.models import VARIANTS
from trainer.evaluation.experiments import COLUMNS, train_all, write_length_flexibility, write_table_and_figures
from trainer.paths import DEFAULT_MANIFEST, REPO_ROOT, RESULTS_DIR
from trainer.scripts.cli import run_main, script_args


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
