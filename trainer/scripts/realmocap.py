"""Train on real motion capture and compare with the baselines: docs/results/realmocap.json and .md, the
real-data section of docs/results/baselines.json and .md, docs/results/realmocap_frames.png.

    nice -n 15 python -m trainer.scripts.realmocap [--epochs 100] [--seeds 0 1 2] [--point-agent PATH]
                                                   [--workers N | --address auto]

Each (experiment, seed) trains as a Ray task (trainer/cluster.py). Finished runs are reused: seed 0's in
runs/realmocap/, seed N's in runs/realmocap_seed<N>/.
"""
import argparse
from pathlib import Path

from trainer.experiments.realmocap import RealMocapSettings, baseline_sets, run_experiments
from trainer.reporting.baselines_report import write_baselines_results
from trainer.reporting.realmocap_report import realmocap_markdown
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, script_args, write_results

DEFAULTS = RealMocapSettings()


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.realmocap", description=__doc__.split("\n\n")[0])
    parser.add_argument("--realmocap", default=DEFAULTS.realmocap)
    parser.add_argument("--epochs", type=int, default=DEFAULTS.epochs,
                        help="iterations of Algorithm 1 per agent (default 100, chosen on validation takes: "
                             "docs/results/realmocap_length.md; paper: 50)")
    parser.add_argument("--preset", default=DEFAULTS.preset)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(DEFAULTS.seeds),
                        help="training seeds; the first seed's agents give the full tables and the figure")
    parser.add_argument("--point-agent", default=None,
                        help="exported pointing agent (.npz) for the guide clips (default: the installed "
                             "agent when trained, else one trained here on the sample library)")
    parser.add_argument("--runs", default=DEFAULTS.runs)
    parser.add_argument("--results", default=DEFAULTS.results)
    parser.add_argument("--import-workers", type=int, default=DEFAULTS.import_workers,
                        help="import the takes the cache lacks with N Blenders at once (Ray tasks; default 1)")
    parser.add_argument("--workers", type=int, default=DEFAULTS.workers,
                        help="a local Ray's training runs at a time (default: one per CPU)")
    parser.add_argument("--address", default=DEFAULTS.address,
                        help="join a Ray cluster: auto (started on this machine by ray start) or ray://HOST:PORT "
                             "(default: a local Ray, no set-up)")
    return parser


def parse_settings(argv=None):
    """RealMocapSettings from the command line."""
    args = build_parser().parse_args(script_args(argv))
    return RealMocapSettings(realmocap=args.realmocap, epochs=args.epochs, preset=args.preset, seeds=tuple(args.seeds),
                             point_agent=args.point_agent, runs=args.runs, results=args.results,
                             import_workers=args.import_workers, workers=args.workers, address=args.address)


def main(argv=None):
    settings = parse_settings(argv)
    results = run_experiments(settings)
    write_results(settings.results, "realmocap", results, realmocap_markdown(results))
    write_baselines_results(Path(settings.results), "real motion capture",
                  "Agents trained on the real waves (takes 001-008 and 021-036, or 5 styles); pointing agent from "
                  f"the sample library for the guide clips. Regenerate: `{results['command']}`.",
                  baseline_sets(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=RUNS_INTERRUPTED))
