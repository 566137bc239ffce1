"""Ask the real-capture wave agents for takes they were trained on, beside leave-one-out retrieval:
docs/results/realmocap_ceiling.{json,md}.

    nice -n 15 python -m trainer.scripts.realmocap_ceiling [--preset end_chunks] [--epochs 100] [--seeds 0 1 2]

The agents are the real-capture experiments' wave agents (trainer/experiments/realmocap_ceiling.py), reused from
runs/realmocap[_seed<N>]/wave[_<preset>]/ and trained there when missing.
"""
from collections.abc import Sequence

from trainer.experiments.realmocap_ceiling import CeilingSettings, run_ceiling
from trainer.reporting.realmocap_ceiling_report import ceiling_markdown
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, write_results


def parse_settings(argv: Sequence[str] | None = None) -> CeilingSettings:
    """CeilingSettings from the command line."""
    return cli.parse_settings(CeilingSettings, argv, prog="python -m trainer.scripts.realmocap_ceiling", doc=__doc__)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_ceiling(settings)
    write_results(settings.results, "realmocap_ceiling", results, ceiling_markdown(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
