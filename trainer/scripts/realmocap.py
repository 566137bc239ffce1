"""Train on real motion capture and compare with the baselines: docs/results/realmocap.json and .md, the
real-data section of docs/results/baselines.json and .md, docs/results/realmocap_frames.png.

    nice -n 15 python -m trainer.scripts.realmocap [--epochs 100] [--seeds 0 1 2] [--point-agent PATH]
                                                   [--workers N | --address auto]

Each (experiment, seed) trains as a Ray task (trainer/cluster.py). Finished runs are reused: seed 0's in
runs/realmocap/, seed N's in runs/realmocap_seed<N>/.
"""
from collections.abc import Sequence
from pathlib import Path

from trainer.experiments.realmocap import RealMocapSettings, baseline_sets, run_experiments
from trainer.reporting.baselines_report import write_baselines_results
from trainer.reporting.realmocap_report import realmocap_markdown
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, write_results


def parse_settings(argv: Sequence[str] | None = None) -> RealMocapSettings:
    """RealMocapSettings from the command line."""
    return cli.parse_settings(RealMocapSettings, argv, prog="python -m trainer.scripts.realmocap", doc=__doc__)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_experiments(settings)
    write_results(settings.results, "realmocap", results, realmocap_markdown(results))
    write_baselines_results(Path(settings.results), "real motion capture",
                  "Agents trained on the real waves (takes 001-008 and 021-036, or 5 styles); pointing agent from "
                  f"the sample library for the guide clips. Regenerate: `{results['command']}`.",
                  baseline_sets(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
