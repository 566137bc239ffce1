"""The wave's rhythm and tempo at play time and the training preset on real capture, as an ablation:
docs/results/realmocap_ablation.{json,md} and docs/results/realmocap_ablation_paths.png.

    nice -n 10 python -m trainer.scripts.realmocap_ablation [--experiments wave holdout] [--seed 0] [--epochs 50]
                                                            [--preset end_chunks] [--compare-presets default]

Trains only the experiments named (one agent per preset, the seed's; reused when
runs/realmocap[_seed<N>]/<name>[_<preset>]/ has it, as trainer.scripts.realmocap reuses it), then plays each with
every setting of trainer/experiments/realmocap_ablation.py.
"""
from collections.abc import Sequence

from trainer.experiments.realmocap_ablation import AblationSettings, run_ablation
from trainer.reporting.realmocap_ablation_report import ablation_markdown
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, write_results


def parse_settings(argv: Sequence[str] | None = None) -> AblationSettings:
    """AblationSettings from the command line."""
    return cli.parse_settings(AblationSettings, argv, prog="python -m trainer.scripts.realmocap_ablation", doc=__doc__)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_ablation(settings)
    write_results(settings.results, "realmocap_ablation", results, ablation_markdown(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
