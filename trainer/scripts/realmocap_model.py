"""Search model and training settings on real capture's validation takes: docs/results/realmocap_model.{json,md}.

    nice -n 15 python -m trainer.scripts.realmocap_model [--presets end_chunks end_chunks_long ...] [--epochs 100]
        [--seeds 0] [--experiments takes style]

Trains one agent per validation experiment, preset and seed of trainer/experiments/realmocap_model.py (reused when
runs/realmocap[_seed<N>]/<experiment>_validation_<epochs>_<preset>/ has it) and scores each with both requests.
"""
from collections.abc import Sequence

from trainer.experiments.realmocap_model import ModelSettings, run_models
from trainer.reporting.realmocap_model_report import model_markdown
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, write_results


def parse_settings(argv: Sequence[str] | None = None) -> ModelSettings:
    """ModelSettings from the command line."""
    return cli.parse_settings(ModelSettings, argv, prog="python -m trainer.scripts.realmocap_model", doc=__doc__)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_models(settings)
    write_results(settings.results, "realmocap_model", results, model_markdown(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
