"""Choose how long to train on real capture, on validation takes no test holds:
docs/results/realmocap_length.{json,md}.

    nice -n 15 python -m trainer.scripts.realmocap_length [--lengths 50 100 200] [--exaggeration-kernels 0.05 0.1 0.15]
        [--tempo-kernels 1.05 1.1 1.15 1.25] [--seed 0] [--preset end_chunks]

Trains one agent per validation experiment and length of trainer/experiments/realmocap_length.py (reused when
runs/realmocap[_seed<N>]/<experiment>_validation_<length>_<preset>/ has it), the longest first, and scores each; then
plays the chosen length's agents with each rhythm rule (exaggeration and tempo kernels, and the request's arm's waves
or both arms').
"""
from collections.abc import Sequence

from trainer.experiments.realmocap_length import LengthSettings, run_lengths
from trainer.reporting.realmocap_length_report import length_markdown
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, write_results


def parse_settings(argv: Sequence[str] | None = None) -> LengthSettings:
    """LengthSettings from the command line."""
    return cli.parse_settings(LengthSettings, argv, prog="python -m trainer.scripts.realmocap_length", doc=__doc__)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_lengths(settings)
    write_results(settings.results, "realmocap_length", results, length_markdown(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
