"""Train one agent on the real waves, guide and goodbye takes and compare it with retrieval:
docs/results/realmocap_guide_bye.json and .md, docs/results/realmocap_guide_bye_paths.png.

    nice -n 15 python -m trainer.scripts.realmocap_gestures [--epochs 50] [--seeds 0 1]

An experiment on CC BY-NC capture: the agents stay in runs/realmocap/gestures/ and runs/realmocap_seed<N>/gestures/
(reused when finished) and never ship.
"""
import argparse
import json
from pathlib import Path

from trainer.experiments.realmocap_gestures import GestureSettings, run_experiment
from trainer.reporting.realmocap_gestures_report import gestures_markdown, paths_figure
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, script_args, write_results

DEFAULTS = GestureSettings()
RESULT = "realmocap_guide_bye"


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.realmocap_gestures",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--realmocap", default=DEFAULTS.realmocap)
    parser.add_argument("--epochs", type=int, default=DEFAULTS.epochs, help="iterations of Algorithm 1 (paper: 50)")
    parser.add_argument("--preset", default=DEFAULTS.preset)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(DEFAULTS.seeds),
                        help="one agent per seed, trained one after another; the first gives the full tables")
    parser.add_argument("--runs", default=DEFAULTS.runs)
    parser.add_argument("--results", default=DEFAULTS.results)
    parser.add_argument("--import-workers", type=int, default=DEFAULTS.import_workers,
                        help="import the takes the cache lacks with N Blenders at once (Ray tasks; default 1)")
    parser.add_argument("--address", default=DEFAULTS.address,
                        help="join a Ray cluster (auto or ray://HOST:PORT; default: a local Ray)")
    return parser


def parse_settings(argv=None):
    """GestureSettings from the command line."""
    args = build_parser().parse_args(script_args(argv))
    return GestureSettings(realmocap=args.realmocap, epochs=args.epochs, preset=args.preset, seeds=tuple(args.seeds),
                           runs=args.runs, results=args.results, import_workers=args.import_workers,
                           address=args.address)


def wave_only_summary(results_dir):
    """The wave-only agent's seed-0 summary on takes 009-010 from realmocap.json, or None without it."""
    path = Path(results_dir) / "realmocap.json"
    if not path.is_file():
        return None
    return json.loads(path.read_text())["wave"]["test_seeds"].get("0")


def main(argv=None):
    settings = parse_settings(argv)
    results, scored = run_experiment(settings)
    out = Path(settings.results)
    out.mkdir(parents=True, exist_ok=True)
    paths_figure(scored["env"], scored["methods"], scored["sets"], out / f"{RESULT}_paths.png")
    write_results(out, RESULT, results, gestures_markdown(results, wave_only_summary(out)))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
