"""Choose how long to train on real capture, on validation takes no test holds:
docs/results/realmocap_length.{json,md}.

    nice -n 15 python -m trainer.scripts.realmocap_length [--lengths 50 100 200] [--exaggeration-kernels 0.05 0.1 0.15]
        [--tempo-kernels 1.05 1.1 1.15 1.25] [--seed 0] [--preset end_chunks]

Trains one agent per validation experiment and length of trainer/experiments/realmocap_length.py (reused when
runs/realmocap[_seed<N>]/<experiment>_validation_<length>_<preset>/ has it), the longest first, and scores each; then
plays the chosen length's agents with each rhythm rule (exaggeration and tempo kernels, and the request's arm's waves
or both arms').
"""
import argparse

from trainer.experiments.realmocap_length import LengthSettings, run_lengths
from trainer.reporting.realmocap_length_report import length_markdown
from trainer.scripts.cli import RUNS_INTERRUPTED, add_real_capture_arguments, run_main, script_args, write_results

DEFAULTS = LengthSettings()


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.realmocap_length",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--lengths", type=int, nargs="+", default=list(DEFAULTS.lengths),
                        help="epoch counts to compare, rising (default 50 100 200)")
    parser.add_argument("--exaggeration-kernels", type=float, nargs="+", default=list(DEFAULTS.exaggeration_kernels),
                        help="exaggeration kernels (sd) to compare (default 0.05 0.1 0.15)")
    parser.add_argument("--tempo-kernels", type=float, nargs="+", default=list(DEFAULTS.tempo_kernels),
                        help="tempo kernels to compare, each the rate factor whose log is its sd in log Hz "
                             "(default 1.05 1.1 1.15 1.25)")
    parser.add_argument("--seed", type=int, default=DEFAULTS.seed, help="the agents' training seed")
    parser.add_argument("--preset", default=DEFAULTS.preset)
    add_real_capture_arguments(parser, DEFAULTS)
    return parser


def parse_settings(argv=None):
    """LengthSettings from the command line."""
    args = build_parser().parse_args(script_args(argv))
    return LengthSettings(lengths=tuple(args.lengths), exaggeration_kernels=tuple(args.exaggeration_kernels),
                          tempo_kernels=tuple(args.tempo_kernels), seed=args.seed, preset=args.preset,
                          realmocap=args.realmocap,
                          runs=args.runs, results=args.results, workers=args.workers)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_lengths(settings)
    write_results(settings.results, "realmocap_length", results, length_markdown(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
