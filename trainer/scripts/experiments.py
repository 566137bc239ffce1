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
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from trainer.experiments.paper import PaperSettings, run_paper
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main


def parse_settings(argv: Sequence[str] | None = None) -> PaperSettings:
    """PaperSettings from the command line."""
    return cli.parse_settings(PaperSettings, argv, prog="python -m trainer.scripts.experiments", doc=__doc__)


def main(argv=None):
    settings = parse_settings(argv)
    finished, flexibility = run_paper(settings)
    print(f"{finished} finished runs\n" + (Path(settings.results) / "table4.md").read_text())
    if flexibility:
        print("length flexibility:", json.dumps(flexibility))
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main, interrupted=RUNS_INTERRUPTED))
