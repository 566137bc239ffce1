"""Issue 10's choices for the agent against the alternatives (trainer/experiments/agent_ablation.py):
docs/results/agent_ablation.{json,md}.

    nice -n 10 python -m trainer.scripts.agent_ablation [--runs runs/agent_ablation] [--results docs/results]

Runs that already finished are not trained again.
"""
from collections.abc import Sequence

from trainer.experiments.agent_ablation import AblationSettings, run_ablation
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main


def parse_settings(argv: Sequence[str] | None = None) -> AblationSettings:
    """AblationSettings from the command line."""
    return cli.parse_settings(AblationSettings, argv, prog="python -m trainer.scripts.agent_ablation", doc=__doc__)


def main(argv=None):
    print(run_ablation(parse_settings(argv)))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
