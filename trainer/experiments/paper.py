"""The paper's Section 4 experiments: one training run per (seed, variant, column), each a Ray task
(trainer/cluster.py), then Table 4 (mean ± sd over seeds, with the baselines and the behaviour metrics, on the held-out
and the harder split), Figure 3 and length flexibility from the finished runs: `run_paper(PaperSettings)`
(`python -m trainer.scripts.experiments` builds the settings from its command line).
"""
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
import torch

from rlanimate_addon.core import behaviours, metrics, spaces
from trainer.agent import checkpoint
from trainer.agent.config import load_preset
from trainer.agent.models import VARIANTS, RLAnimateAgent
from trainer.blender_io.clip_session import LibrarySession
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.evaluation import behaviour, scoring
from trainer.evaluation.baselines import AgentMethod, ClassMean, NearestClip, NoMotion, mean_start_pose
from trainer.evaluation.harder_split import harder_clips
from trainer.experiments.options import require_values, some_of
from trainer.experiments.run import RunSettings, is_finished, train_runs
from trainer.files import atomic_write_text
from trainer.paths import DEFAULT_MANIFEST, REPO_ROOT, RESULTS_DIR, seed_folder
from trainer.reporting import plots
from trainer.reporting.table4 import table4_markdown

COLUMNS = tuple(plots.COLUMN_LABELS)  # wave, point, both
#: The paper's training lengths (Figure 3): 50 epochs for one behaviour, 100 for both.
PAPER_EPOCHS = {column: 50 * len(behaviours.training_set(column, spaces.PAPER_SPACE.names)) for column in COLUMNS}
#: Random unseen pointing targets per arm at which every pointing agent's own aim is measured.
RANDOM_TARGETS = 100
LENGTH_SCALES = tuple(float(s) for s in np.round(np.arange(0.3, 1.71, 0.1), 2))


@dataclass(frozen=True)
class PaperSettings:
    """What the Section 4 experiments run: every (seed, variant, column) for the paper's epochs x `epoch_scale`."""
    preset: str = "default"  # config preset of every run: debug, default or paper
    epoch_scale: float = 1.0  # fraction of the paper's 50 / 100 epochs to train (CPU budget)
    variants: Annotated[tuple[str, ...], some_of(VARIANTS)] = VARIANTS  # the variants (Table 4's rows) to train
    columns: Annotated[tuple[str, ...], some_of(COLUMNS)] = COLUMNS  # the behaviours (Table 4's columns) to train
    clips: str = str(DEFAULT_MANIFEST)  # clip library: a manifest.json or the folder that holds one
    runs: str = str(REPO_ROOT / "runs" / "experiments")  # seed 0's runs; seed N's go to the sibling <runs>_seed<N>
    results: str = str(RESULTS_DIR)  # where table4.json and .md and the figures go
    eval_every: int = 5  # evaluate each run on seen and unseen clips every N epochs (Figure 3)
    seeds: tuple[int, ...] = (0, 1, 2)  # training seeds: one run per seed, variant and column
    # join a Ray cluster: auto (started on this machine by ray start) or ray://HOST:PORT (None: a local Ray, no set-up)
    address: str | None = None
    workers: int | None = None  # a local Ray's training runs at a time (None: one per CPU)
    skip_training: bool = False  # report the runs that finished, train none

    def __post_init__(self) -> None:
        require_values(self, "variants", "columns", "seeds")


def run_folder(settings, seed, variant, column):
    """<runs>/<variant>_<column> for seed 0, <runs>_seed<N>/<variant>_<column> for another seed."""
    return seed_folder(settings.runs, seed) / f"{variant}_{column}"


def planned_epochs(settings, column):
    return max(1, int(round(PAPER_EPOCHS[column] * settings.epoch_scale)))


def run_settings(settings: PaperSettings, seed: int, variant: str, column: str) -> RunSettings:
    """The training run of (seed, variant, column), resumed from its checkpoint when it has one."""
    folder = run_folder(settings, seed, variant, column)
    return RunSettings(output=str(folder), behaviour=column, clips=settings.clips,
                       epochs=planned_epochs(settings, column), seed=seed, preset=settings.preset, variant=variant,
                       eval_every=settings.eval_every, resume=(folder / checkpoint.FILENAME).is_file(), progress=False)


def train_all(settings: PaperSettings) -> None:
    """Train every unfinished (seed, variant, column) as a Ray task (trainer/cluster.py); each writes its
    outputs and its train.log into its folder. Raises RuntimeError when a run fails."""
    pending = [run_settings(settings, s, v, c) for s in settings.seeds for v in settings.variants
               for c in settings.columns if not is_finished(run_folder(settings, s, v, c), planned_epochs(settings, c))]
    for run, _ in train_runs(pending, settings.address, settings.workers):
        print(f"finished {run.variant} {run.behaviour} seed {run.seed}", flush=True)


def load_run(folder):
    report = json.loads((folder / "report.json").read_text())
    history = [json.loads(line) for line in (folder / "metrics.jsonl").read_text().splitlines()]
    return report, history


def finished_runs(settings):
    """{(seed, variant, column): folder} of the runs that finished their planned epochs."""
    return {(s, v, c): run_folder(settings, s, v, c) for s in settings.seeds for v in settings.variants
            for c in settings.columns if is_finished(run_folder(settings, s, v, c), planned_epochs(settings, c))}


def evaluate_runs(settings, runs, session):
    """{split: {column: {method: [behaviour.summarise of each seed]}}}: every finished run's agent (its
    agent.npz, numpy runtime) and each baseline on the held-out clips and the harder split; an agent trained
    on one behaviour is asked for that behaviour only."""
    train = session.train_clips
    lengths = behaviour.class_lengths(train)
    splits = {"held-out": session.test_clips, "harder": harder_clips()}
    baselines = {"no_motion": NoMotion(mean_start_pose(train)), "class_mean": ClassMean(train),
                 "nearest_clip": NearestClip(train), "procedural_ik": ProceduralIK(mean_start_pose(train))}

    def summary(method, clips):
        return behaviour.summarise(behaviour.request_rows(method, clips, session.references, session.describe,
                                                          lengths))

    results = {}
    for split, clips in splits.items():
        for column in settings.columns:
            wanted = [c for c in clips if c.behaviour in behaviours.training_set(column, spaces.PAPER_SPACE.names)]
            entry = results.setdefault(split, {}).setdefault(column, {})
            for (_seed, variant, run_column), folder in sorted(runs.items()):
                if run_column == column:
                    entry.setdefault(variant, []).append(summary(AgentMethod(folder / "agent.npz"), wanted))
            for name, method in baselines.items():
                entry[name] = [summary(method, wanted)]
    return results


def random_target_aim(settings, runs, session):
    """{column: {variant: [per seed: {'left', 'right': {'median', 'max'}}]}}: each pointing agent's own aim
    (no aim correction, degrees at the hold) at RANDOM_TARGETS random unseen targets per arm, at the
    class-average pointing length."""
    frames = behaviour.class_lengths(session.train_clips)[behaviours.POINT]
    results = {}
    for (_seed, variant, column), folder in sorted(runs.items()):
        if behaviours.POINT in behaviours.training_set(column, spaces.PAPER_SPACE.names):
            sweeps = behaviour.random_target_sweeps(AgentMethod(folder / "agent.npz"), frames, session.describe,
                                                     RANDOM_TARGETS)
            results.setdefault(column, {}).setdefault(variant, []).append(
                {arm: {"median": sweep["median_angle"], "max": sweep["max_angle"]} for arm, sweep in sweeps.items()})
    return results


def aggregate(per_seed: list[dict]) -> dict:
    """[summary per seed] -> {behaviour: {metric: {mean, sd, n}}}; sd 0 for one value, NaN values (a ratio
    to a zero reference) left out."""
    out: dict[str, dict[str, dict[str, float | int | None]]] = {}
    for key in per_seed[0]:
        out[key] = {}
        for metric in per_seed[0][key]:
            values = np.array([s[key][metric] for s in per_seed], dtype=np.float64)
            values = values[~np.isnan(values)]
            out[key][metric] = {"mean": float(np.mean(values)) if len(values) else None,
                                "sd": float(np.std(values, ddof=1)) if len(values) > 1 else 0.0, "n": len(values)}
    return out


def write_table_and_figures(settings, results, session):
    """table4.json/.md over the finished runs, and Figure 3 from the first seed's histories; returns the
    number of finished runs."""
    runs = finished_runs(settings)
    evaluated = evaluate_runs(settings, runs, session)
    table = {split: {column: {method: aggregate(per_seed) for method, per_seed in methods.items()}
                     for column, methods in columns.items()} for split, columns in evaluated.items()}
    training, histories = {}, {}
    for (seed, variant, column), folder in sorted(runs.items()):
        report, history = load_run(folder)
        training[f"{variant} {column} seed {seed}"] = {
            "variant": variant, "column": column, "seed": seed, "episodes": report["episodes"],
            "train_seconds": report["train_seconds"], "train_cpu_seconds": report["train_cpu_seconds"],
            "held_out_score": report["held_out"]["score"], "seen_score": report["training"]["score"]}
        if seed == settings.seeds[0]:
            histories.setdefault(variant, {})[column] = history
    seeds = " ".join(str(s) for s in settings.seeds)
    planned = len(settings.seeds) * len(settings.variants) * len(settings.columns)
    described = (f"Preset `{settings.preset}`, seeds {seeds}, epochs = {settings.epoch_scale:g} x the paper's "
                 f"(50 for one behaviour, 100 for both; an epoch is one iteration of Algorithm 1); "
                 f"{len(runs)} of {planned} runs finished. "
                 f"Regenerate: `nice -n 10 python -m trainer.scripts.experiments --preset {settings.preset} "
                 f"--epoch-scale {settings.epoch_scale:g} --seeds {seeds}`.")
    aim = {column: {variant: aggregate(per_seed) for variant, per_seed in variants.items()}
           for column, variants in random_target_aim(settings, runs, session).items()}
    report = {"settings": described, "seeds": list(settings.seeds), "table": table, "random_targets": aim,
              "random_target_count": RANDOM_TARGETS, "training": training}
    atomic_write_text(results / "table4.json", json.dumps(report, indent=1) + "\n")
    atomic_write_text(results / "table4.md", table4_markdown(report))
    for split in ("seen", "unseen"):
        plots.figure3(histories, results / f"figure3_{split}.png", split)
    return len(runs)


def load_trained_agent(folder: Path) -> RLAnimateAgent:
    """The torch agent of a finished run, rebuilt from its checkpoint's own settings (preset and variant)."""
    saved = checkpoint.load(folder / checkpoint.FILENAME)
    agent = RLAnimateAgent(load_preset(saved["arguments"]["preset"])[0], saved["arguments"]["variant"])
    agent.load_state_dict(saved["trainer"]["agent"])
    return agent


def write_length_flexibility(settings, results, session):
    """Section 4.4 for the first seed's RLAnimate both-behaviour agent on the held-out clips."""
    folder = run_folder(settings, settings.seeds[0], "rlanimate", behaviours.BOTH)
    if not is_finished(folder, planned_epochs(settings, behaviours.BOTH)):
        return None
    agent = load_trained_agent(folder)
    test = scoring.select_clips(session.test_clips, spaces.PAPER_SPACE.names)
    flexibility = scoring.length_flexibility(agent, session.env, test, session.train_clips, LENGTH_SCALES)
    atomic_write_text(results / "length_flexibility.json", json.dumps(flexibility, indent=2) + "\n")
    plots.length_flexibility(flexibility, results / "length_flexibility.png", metrics.ARTEFACT_THRESHOLD)
    return flexibility


def run_paper(settings: PaperSettings) -> tuple[int, dict | None]:
    """Train what is unfinished (unless `skip_training`), then write Table 4, Figure 3 and length flexibility
    into `settings.results`; returns (finished runs, length flexibility or None)."""
    torch.set_num_threads(1)
    results = Path(settings.results)
    results.mkdir(parents=True, exist_ok=True)
    if not settings.skip_training:
        train_all(settings)
    session = LibrarySession(settings.clips)
    finished = write_table_and_figures(settings, results, session)
    return finished, write_length_flexibility(settings, results, session)
