"""Regenerate the paper's Section 4 results: Table 4 (over several seeds, with the baselines and the
behaviour metrics, on the held-out and a harder split), Figure 3 and length flexibility.

    nice -n 10 python -m trainer.scripts.experiments [--preset default] [--epoch-scale 1.0] [--seeds 0 1 2]
                                                    [--workers 2 | --address auto] [--skip-training]

Trains the four variants (RLAnimate and its three ablations) on each column (wave, point, both)
for the paper's 50 / 100 epochs times --epoch-scale, for each seed, each run a Ray task: on a local Ray,
--workers at a time (default one per CPU), or on the cluster --address joins (docs/TRAINING.md), into
runs/experiments/<variant>_<column>/ (seed 0) and
runs/experiments_seed<N>/<variant>_<column>/. Runs that already finished are kept and interrupted ones
resume from their checkpoints; --skip-training reports the finished runs only. Then every finished run's
agent and the baselines (no motion, class mean, nearest clip, procedural IK) answer the library's held-out
requests and a harder split (trainer/evaluation/harder_split.py), and it writes to docs/results/:
    table4.json   per split, column and behaviour: {method: {metric: {mean, sd, n}}} over the seeds, and
                  each run's training figures
    table4.md     the same as tables, methods as rows, mean ± sd over the seeds that finished
    figure3_seen.png, figure3_unseen.png   score over epochs on seen and unseen clips (first seed)
    length_flexibility.json/.png           smoothness of the RLAnimate both-agent's held-out gestures
                                           time-scaled 0.3x-1.7x the class average length (first seed)
"""
import argparse
import json
import sys
from pathlib import Path

from trainer.agent.models import VARIANTS
from trainer.experiments.paper import COLUMNS, PaperSettings, run_paper
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, script_args

DEFAULTS = PaperSettings()


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.experiments", description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default=DEFAULTS.preset)
    parser.add_argument("--epoch-scale", type=float, default=DEFAULTS.epoch_scale,
                        help="fraction of the paper's 50 / 100 epochs to train (CPU budget)")
    parser.add_argument("--variants", nargs="+", choices=VARIANTS, default=list(DEFAULTS.variants))
    parser.add_argument("--columns", nargs="+", choices=COLUMNS, default=list(DEFAULTS.columns))
    parser.add_argument("--clips", default=DEFAULTS.clips)
    parser.add_argument("--runs", default=DEFAULTS.runs,
                        help="seed 0's runs; seed N's go to the sibling folder <runs>_seed<N>")
    parser.add_argument("--results", default=DEFAULTS.results)
    parser.add_argument("--eval-every", type=int, default=DEFAULTS.eval_every)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(DEFAULTS.seeds))
    parser.add_argument("--workers", type=int, default=DEFAULTS.workers,
                        help="a local Ray's training runs at a time (default: one per CPU)")
    parser.add_argument("--address", default=DEFAULTS.address,
                        help="join a Ray cluster: auto (started on this machine by ray start) or ray://HOST:PORT "
                             "(default: a local Ray, no set-up)")
    parser.add_argument("--skip-training", action="store_true", help="report the runs that finished, train none")
    return parser


def parse_settings(argv=None):
    """PaperSettings from the command line."""
    args = build_parser().parse_args(script_args(argv))
    return PaperSettings(preset=args.preset, epoch_scale=args.epoch_scale, variants=tuple(args.variants),
                         columns=tuple(args.columns), clips=args.clips, runs=args.runs, results=args.results,
                         eval_every=args.eval_every, seeds=tuple(args.seeds), address=args.address,
                         workers=args.workers, skip_training=args.skip_training)


def main(argv=None):
    settings = parse_settings(argv)
    finished, flexibility = run_paper(settings)
    print(f"{finished} finished runs\n" + (Path(settings.results) / "table4.md").read_text())
    if flexibility:
        print("length flexibility:", json.dumps(flexibility))
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main, interrupted=RUNS_INTERRUPTED))
