"""Train one agent on the real waves, guide and goodbye takes and compare it with retrieval:
docs/results/realmocap_guide_bye.json and .md, docs/results/realmocap_guide_bye_paths.png.

    nice -n 15 python -m trainer.scripts.realmocap_gestures [--epochs 50] [--seeds 0 1]

An experiment on CC BY-NC capture: the agents stay in runs/realmocap/gestures/ and runs/realmocap_seed<N>/gestures/
(reused when finished) and never ship.
"""
import json
from collections.abc import Sequence
from pathlib import Path

from trainer.experiments.realmocap_gestures import GestureSettings, run_experiment
from trainer.reporting.realmocap_gestures_report import gestures_markdown, paths_figure
from trainer.scripts import cli
from trainer.scripts.cli import RUNS_INTERRUPTED, run_main, write_results

RESULT = "realmocap_guide_bye"


def parse_settings(argv: Sequence[str] | None = None) -> GestureSettings:
    """GestureSettings from the command line."""
    return cli.parse_settings(GestureSettings, argv, prog="python -m trainer.scripts.realmocap_gestures", doc=__doc__)


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
