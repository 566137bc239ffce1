"""Issue 10's choices for the agent against the alternatives (trainer/experiments/agent_ablation.py):
docs/results/agent_ablation.{json,md}.

    nice -n 10 python -m trainer.scripts.agent_ablation [--runs runs/agent_ablation] [--results docs/results]

Runs that already finished are not trained again.
"""
import argparse

from trainer.experiments.agent_ablation import ABLATIONS, AblationSettings, run_ablation
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, script_args

DEFAULTS = AblationSettings()


def parse_settings(argv=None):
    """AblationSettings from the command line."""
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.agent_ablation",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", default=DEFAULTS.runs)
    parser.add_argument("--results", default=DEFAULTS.results)
    parser.add_argument("--targets", type=int, default=DEFAULTS.targets, help="random pointing targets per arm")
    parser.add_argument("--only", nargs="*", choices=sorted(ABLATIONS),
                        help="train and measure only these; the other rows stay as agent_ablation.json has them")
    parser.add_argument("--workers", type=int, default=DEFAULTS.workers,
                        help="a local Ray's training runs at a time (default: one per CPU)")
    parser.add_argument("--address", default=DEFAULTS.address,
                        help="join a Ray cluster: auto or ray://HOST:PORT (default: a local Ray)")
    args = parser.parse_args(script_args(argv))
    return AblationSettings(runs=args.runs, results=args.results, targets=args.targets, only=tuple(args.only or ()),
                            address=args.address, workers=args.workers)


def main(argv=None):
    print(run_ablation(parse_settings(argv)))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
