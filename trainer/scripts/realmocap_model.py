"""Search model and training settings on real capture's validation takes: docs/results/realmocap_model.{json,md}.

    nice -n 15 python -m trainer.scripts.realmocap_model [--presets end_chunks end_chunks_long ...] [--epochs 100]
        [--seeds 0] [--experiments takes style]

Trains one agent per validation experiment, preset and seed of trainer/experiments/realmocap_model.py (reused when
runs/realmocap[_seed<N>]/<experiment>_validation_<epochs>_<preset>/ has it) and scores each with both requests.
"""
import argparse

from trainer.experiments.realmocap_model import ModelSettings, run_models
from trainer.reporting.realmocap_model_report import model_markdown
from trainer.scripts.cli import add_real_capture_arguments, run_main, script_args, write_results

DEFAULTS = ModelSettings()


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.realmocap_model",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--presets", nargs="+", default=list(DEFAULTS.presets),
                        help="config presets to compare, the recipe first (default %(default)s)")
    parser.add_argument("--epochs", type=int, default=DEFAULTS.epochs)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(DEFAULTS.seeds))
    parser.add_argument("--experiments", nargs="+", default=list(DEFAULTS.experiments),
                        help="validation experiments: takes (007-008) and/or style (normal)")
    add_real_capture_arguments(parser, DEFAULTS)
    return parser


def main(argv=None):
    args = build_parser().parse_args(script_args(argv))
    settings = ModelSettings(presets=tuple(args.presets), epochs=args.epochs, seeds=tuple(args.seeds),
                             experiments=tuple(args.experiments), realmocap=args.realmocap, runs=args.runs,
                             results=args.results, workers=args.workers)
    results = run_models(settings)
    write_results(settings.results, "realmocap_model", results, model_markdown(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main))
