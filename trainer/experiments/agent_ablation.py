"""Issue 10's choices for the agent, measured against the alternatives: one-behaviour agents trained
with each, their behaviour measures on the held-out requests -> docs/results/agent_ablation.{json,md}.

`run_ablation(AblationSettings)`; `python -m trainer.scripts.agent_ablation` builds the settings from its
command line.

Waves: the rhythm in the objective with the waving-wrist term (the default), without the wrist term,
the paper's objective (exaggeration only), and the stochastic behaviour state carrying the wave
(single_state, its posterior on the clip's description during updates, its prior at play). Points: the pointing
term with random targets (the default), without the random targets, and with neither. Runs that already
finished are not trained again.
"""
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
import torch

from rlanimate_addon.core import behaviours, kinematics, spaces
from trainer.agent import checkpoint
from trainer.agent.config import load_preset
from trainer.blender_io.clip_session import LibrarySession
from trainer.evaluation import behaviour
from trainer.evaluation.baselines import AgentMethod
from trainer.experiments.options import some_of
from trainer.experiments.run import RunSettings, train_runs
from trainer.files import atomic_write_text
from trainer.paths import DEFAULT_MANIFEST, REPO_ROOT, RESULTS_DIR, shown
from trainer.reporting.tables import markdown_table

_CHOSEN = load_preset("default")[1]
#: name: (behaviour, preset, variant, label)
ABLATIONS = {
    "wave_rhythm": ("wave", "default", "rlanimate", "rhythm in the objective and the wrist term (chosen)"),
    "wave_no_wrist_term": ("wave", "no_wrist_term", "rlanimate", "rhythm in the objective, no wrist term"),
    "wave_paper_objective": ("wave", "paper_wave_objective", "rlanimate", "the paper's objective"),
    "wave_reference_posterior": ("wave", "reference_posterior", "single_state",
                                 "behaviour state on the clip, prior at play"),
    "point_random_targets": ("point", "default", "rlanimate",
                             f"pointing term and {_CHOSEN.random_targets} random targets per iteration, range + "
                             f"{_CHOSEN.random_target_margin_deg:g} degrees, each drawn into updates at "
                             f"{_CHOSEN.random_target_weight:.2g}x a clip's chance (chosen)"),
    "point_no_random_targets": ("point", "no_random_targets", "rlanimate", "pointing term only"),
    "point_no_pointing_term": ("point", "no_pointing_term", "rlanimate", "neither"),
}
SEEDS = (1, 2, 3)


@dataclass(frozen=True)
class AblationSettings:
    """Which ablations to train (unless finished) and measure, and where."""
    runs: str = str(REPO_ROOT / "runs" / "agent_ablation")  # the training runs' folder, one subfolder per ablation
    results: str = str(RESULTS_DIR)  # where agent_ablation.json and .md go
    targets: int = 100  # random pointing targets per arm
    # train and measure only these (none: every ablation); the other rows stay as agent_ablation.json has them
    only: Annotated[tuple[str, ...], some_of(ABLATIONS)] = ()
    address: str | None = None  # join a Ray cluster: auto or ray://HOST:PORT (None: a local Ray)
    workers: int | None = None  # a local Ray's training runs at a time (None: one per CPU)


def describe(rotvecs):
    return kinematics.describe(np.asarray(rotvecs, dtype=np.float64))


def measure(path, behaviour_name, session, target_count):
    """The behaviour measures of the agent at `path` on the held-out requests of its behaviour."""
    method = AgentMethod(path)
    lengths = behaviour.class_lengths(session.train_clips)
    clips = [c for c in session.test_clips
             if c.behaviour in behaviours.training_set(behaviour_name, spaces.PAPER_SPACE.names)]
    rows = behaviour.request_rows(method, clips, session.references, describe, lengths)
    result = {"held_out": behaviour.summarise(rows)[behaviour_name],
              "update_steps": method.agent.metadata["train_config"]["update_steps"]}
    if behaviour_name == "wave":
        result["seeded"] = behaviour.summarise(sum((behaviour.request_rows(
            method, clips, session.references, describe, lengths, seed=seed) for seed in SEEDS), []))["wave"]
        result["sweep"] = {arm.lower(): behaviour.exaggeration_sweep(method, arm, lengths[behaviours.WAVE], describe)
                           for arm in ("LEFT", "RIGHT")}
        result["variation"] = float(np.median([r["variation"] for r in behaviour.seed_variation(
            method, clips, describe, SEEDS)]))
    else:
        result["random_targets"] = behaviour.random_target_sweeps(method, lengths[behaviours.POINT], describe,
                                                                  target_count)
    return result


def markdown(results, command):
    lines = [
        "# Issue 10's agent choices against their alternatives",
        "",
        "One-behaviour agents (preset `default` or the named ablation preset, seed 0, 50 epochs), measured with "
        "`core.behaviour_metrics` (docs/METRICS.md) on the sample library's held-out requests at each clip's "
        "own length, deterministic rollouts of the numpy runtime; T: the run's updates per epoch; "
        "seeded = variation seeds "
        f"{', '.join(map(str, SEEDS))}. Regenerate: `{command}`.",
        "",
        "## Wave (4 held-out requests)",
        "",
    ]
    rows = []
    for name, result in results.items():
        if ABLATIONS[name][0] != "wave":
            continue
        held, seeded = result["held_out"], result["seeded"]
        rows.append(
            [
                ABLATIONS[name][3],
                result["update_steps"],
                f"{held['accepted_share'] * 4:.0f} / 4",
                f"{seeded['accepted_share'] * 4 * len(SEEDS):.0f} / {4 * len(SEEDS)}",
                f"{held['swing_ratio_min']:.2f} / {held['swing_ratio_median']:.2f} / {held['swing_ratio_max']:.2f}",
                f"{held['frequency_ratio_median']:.2f}",
                f"{held['cycles_min']:.0f} / {held['cycles_median']:.1f}",
                "yes" if all(s["swing_rising"] for s in result["sweep"].values()) else "no",
                f"{100 * result['variation']:.1f}",
                f"{held['elevation_first_error_max']:.1f}",
                f"{held['elevation_last_error_max']:.1f}",
                f"{held['score']:.2f}",
                f"{held['smoothness']:.2f}",
            ]
        )
    lines += markdown_table(["method", "T", "accepted", "accepted, seeded", "swing ratio min / median / max",
                             "frequency ratio", "cycles min / median", "swing rises with exaggeration",
                             "seed variation (cm)", "first-frame elevation error (deg, max)",
                             "last-frame error (deg, max)", "score", "smoothness"], rows)
    counts = {len(r["random_targets"]["left"]["angles"]) for r in results.values() if "random_targets" in r}
    lines += ["", f"## Point (6 held-out requests; {' or '.join(map(str, sorted(counts)))} random targets "
              "1.5-4 m per arm)", ""]
    rows = []
    for name, result in results.items():
        if ABLATIONS[name][0] != "point":
            continue
        held, random = result["held_out"], result["random_targets"]
        rows.append([ABLATIONS[name][3], result["update_steps"],
                     f"{held['pointing_angle_median']:.2f} / {held['pointing_angle_max']:.2f}",
                     f"{random['left']['median_angle']:.2f} / {random['left']['max_angle']:.2f}",
                     f"{random['right']['median_angle']:.2f} / {random['right']['max_angle']:.2f}",
                     f"{held['elevation_first_error_max']:.1f}", f"{held['score']:.2f}", f"{held['smoothness']:.2f}"])
    lines += markdown_table(["method", "T", "raw angle held out (deg, median / max)", "random left", "random right",
                             "first-frame elevation error (deg, max)", "score", "smoothness"], rows)
    return "\n".join(lines) + "\n"


def run_ablation(settings: AblationSettings) -> str:
    """Train the unfinished ablations of `settings` (all, or `only`), measure them, and write
    agent_ablation.json and .md into `settings.results`; returns the markdown."""
    torch.set_num_threads(1)
    names = settings.only or tuple(ABLATIONS)
    folders = {name: Path(settings.runs) / name for name in names}
    untrained = [RunSettings(str(folders[name]), behaviour=ABLATIONS[name][0], preset=ABLATIONS[name][1],
                             variant=ABLATIONS[name][2], eval_every=0, progress=False,
                             resume=(folders[name] / checkpoint.FILENAME).is_file())  # a stopped run continues
                 for name in names if not (folders[name] / "report.json").is_file()]
    for run, _ in train_runs(untrained, settings.address, settings.workers):
        print(f"trained {Path(run.output).name}", flush=True)
    session = LibrarySession(DEFAULT_MANIFEST)
    results_dir = Path(settings.results)
    results_json = results_dir / "agent_ablation.json"
    results = json.loads(results_json.read_text()) if settings.only and results_json.is_file() else {}
    for name in names:
        output = Path(settings.runs) / name
        results[name] = measure(output / "agent.npz", ABLATIONS[name][0], session, settings.targets)
        print(name, json.dumps(results[name]["held_out"]), flush=True)
    results = {name: results[name] for name in ABLATIONS if name in results}
    command = f"nice -n 10 python -m trainer.scripts.agent_ablation --runs {shown(settings.runs)}"
    results_dir.mkdir(parents=True, exist_ok=True)
    atomic_write_text(results_json, json.dumps(results, indent=1) + "\n")  # it holds rows not rerun here
    text = markdown(results, command)
    atomic_write_text(results_dir / "agent_ablation.md", text)
    return text
