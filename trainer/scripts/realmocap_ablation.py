"""The wave's rhythm and tempo at play time and the training preset on real capture, as an ablation:
docs/results/realmocap_ablation.{json,md} and docs/results/realmocap_ablation_paths.png.

    nice -n 10 python -m trainer.scripts.realmocap_ablation [--experiments wave holdout] [--seed 0] [--epochs 50]
                                                            [--preset end_chunks] [--compare-presets default]

Trains only the experiments named (one agent per preset, the seed's; reused when
runs/realmocap[_seed<N>]/<name>[_<preset>]/ has it, as trainer.scripts.realmocap reuses it), then plays each with
every setting of trainer/experiments/realmocap_ablation.py.
"""
import argparse

from trainer.experiments.realmocap_ablation import EXPERIMENTS, AblationSettings, run_ablation
from trainer.reporting.realmocap_ablation_report import ablation_markdown
from trainer.scripts.cli import RUNS_INTERRUPTED, add_real_capture_arguments, run_main, script_args, write_results

DEFAULTS = AblationSettings()


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.realmocap_ablation",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--experiments", nargs="+", choices=list(EXPERIMENTS), default=list(DEFAULTS.experiments),
                        help="which agents to train and play: wave (tested on takes 009-010), holdout (unseen styles)")
    parser.add_argument("--seed", type=int, default=DEFAULTS.seed, help="the agents' training seed")
    parser.add_argument("--epochs", type=int, default=DEFAULTS.epochs)
    parser.add_argument("--preset", default=DEFAULTS.preset, help="the agents whose play-time settings vary")
    parser.add_argument("--compare-presets", nargs="*", default=list(DEFAULTS.compare_presets),
                        help="agents trained with these presets too, played as trained and asked the tempo")
    add_real_capture_arguments(parser, DEFAULTS)
    return parser


def parse_settings(argv=None):
    """AblationSettings from the command line."""
    args = build_parser().parse_args(script_args(argv))
    return AblationSettings(experiments=tuple(dict.fromkeys(args.experiments)), seed=args.seed, epochs=args.epochs,
                            preset=args.preset, compare_presets=tuple(dict.fromkeys(args.compare_presets)),
                            realmocap=args.realmocap, runs=args.runs, results=args.results,
                            workers=args.workers)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_ablation(settings)
    write_results(settings.results, "realmocap_ablation", results, ablation_markdown(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
