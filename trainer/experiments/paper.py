"""The paper's Section 4 experiments: one training run per (seed, variant, column), each in its own
process, then Table 4 (mean ± sd over seeds, with the baselines and the behaviour metrics, on the held-out
and the harder split), Figure 3 and length flexibility from the finished runs
(`python -m trainer.scripts.experiments`).

`options` is the experiments' command line (trainer/scripts/experiments.py): preset, epoch_scale,
variants, columns, clips, runs, results, eval_every, seeds, jobs.
"""
import json
import subprocess
import sys
import time

import numpy as np

from rlanimate_addon.core import metrics
from trainer.agent import checkpoint
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.evaluation import behaviour, scoring
from trainer.evaluation.baselines import AgentMethod, ClassMean, NearestClip, NoMotion, mean_start_pose
from trainer.evaluation.harder_split import harder_clips
from trainer.files import atomic_write_text
from trainer.paths import REPO_ROOT, seed_folder
from trainer.reporting import plots
from trainer.reporting.table4 import table4_markdown

COLUMNS = tuple(plots.COLUMN_LABELS)  # wave, point, both
#: The paper's training lengths (Figure 3): 50 epochs for one behaviour, 100 for both.
PAPER_EPOCHS = {"point": 50, "wave": 50, "both": 100}
#: Random unseen pointing targets per arm at which every pointing agent's own aim is measured.
RANDOM_TARGETS = 100
LENGTH_SCALES = tuple(float(s) for s in np.round(np.arange(0.3, 1.71, 0.1), 2))


def run_folder(options, seed, variant, column):
    """<runs>/<variant>_<column> for seed 0, <runs>_seed<N>/<variant>_<column> for another seed."""
    return seed_folder(options.runs, seed) / f"{variant}_{column}"


def planned_epochs(options, column):
    return max(1, int(round(PAPER_EPOCHS[column] * options.epoch_scale)))


def is_finished(folder, epochs):
    report = folder / "report.json"
    return report.is_file() and json.loads(report.read_text())["epochs"] == epochs


def train_command(options, seed, variant, column):
    folder = run_folder(options, seed, variant, column)
    command = [sys.executable, "-m", "trainer.scripts.train", "--behaviour", column,
               "--variant", variant, "--preset", options.preset, "--clips", options.clips,
               "--epochs", str(planned_epochs(options, column)), "--seed", str(seed),
               "--output", str(folder), "--eval-every", str(options.eval_every), "--quiet"]
    return command + (["--resume"] if (folder / checkpoint.FILENAME).is_file() else [])


def train_all(options):
    """Run every unfinished (seed, variant, column), --jobs processes at a time; raise if one fails."""
    pending = [(s, v, c) for s in options.seeds for v in options.variants for c in options.columns
               if not is_finished(run_folder(options, s, v, c), planned_epochs(options, c))]
    running = []
    while pending or running:
        while pending and len(running) < options.jobs:
            seed, variant, column = pending.pop(0)
            folder = run_folder(options, seed, variant, column)
            folder.mkdir(parents=True, exist_ok=True)
            log = open(folder / "train.log", "w")
            running.append((seed, variant, column, log, subprocess.Popen(
                train_command(options, seed, variant, column), stdout=log, stderr=subprocess.STDOUT, cwd=REPO_ROOT)))
        time.sleep(1.0)
        for entry in list(running):
            seed, variant, column, log, process = entry
            if process.poll() is not None:
                log.close()
                running.remove(entry)
                if process.returncode != 0:
                    raise RuntimeError(f"{variant} {column} seed {seed} failed: see "
                                       f"{run_folder(options, seed, variant, column)}/train.log")
                print(f"finished {variant} {column} seed {seed}", flush=True)


def load_run(folder):
    report = json.loads((folder / "report.json").read_text())
    history = [json.loads(line) for line in (folder / "metrics.jsonl").read_text().splitlines()]
    return report, history


def finished_runs(options):
    """{(seed, variant, column): folder} of the runs that finished their planned epochs."""
    return {(s, v, c): run_folder(options, s, v, c) for s in options.seeds for v in options.variants
            for c in options.columns if is_finished(run_folder(options, s, v, c), planned_epochs(options, c))}


def column_behaviours(column):
    return ("WAVE", "POINT") if column == "both" else (column.upper(),)


def evaluate_runs(options, runs, session):
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
        for column in options.columns:
            wanted = [c for c in clips if c.behaviour.upper() in column_behaviours(column)]
            entry = results.setdefault(split, {}).setdefault(column, {})
            for (seed, variant, run_column), folder in sorted(runs.items()):
                if run_column == column:
                    entry.setdefault(variant, []).append(summary(AgentMethod(folder / "agent.npz"), wanted))
            for name, method in baselines.items():
                entry[name] = [summary(method, wanted)]
    return results


def random_target_aim(options, runs, session):
    """{column: {variant: [per seed: {'left', 'right': {'median', 'max'}}]}}: each pointing agent's own aim
    (no aim correction, degrees at the hold) at RANDOM_TARGETS random unseen targets per arm, at the
    class-average pointing length."""
    frames = behaviour.class_lengths(session.train_clips)["POINT"]
    results = {}
    for (seed, variant, column), folder in sorted(runs.items()):
        if "POINT" in column_behaviours(column):
            sweeps = behaviour.random_target_sweeps(AgentMethod(folder / "agent.npz"), frames, session.describe,
                                                     RANDOM_TARGETS)
            results.setdefault(column, {}).setdefault(variant, []).append(
                {arm: {"median": sweep["median_angle"], "max": sweep["max_angle"]} for arm, sweep in sweeps.items()})
    return results


def aggregate(per_seed):
    """[summary per seed] -> {behaviour: {metric: {mean, sd, n}}}; sd 0 for one value, NaN values (a ratio
    to a zero reference) left out."""
    out = {}
    for key in per_seed[0]:
        out[key] = {}
        for metric in per_seed[0][key]:
            values = np.array([s[key][metric] for s in per_seed], dtype=np.float64)
            values = values[~np.isnan(values)]
            out[key][metric] = {"mean": float(np.mean(values)) if len(values) else None,
                                "sd": float(np.std(values, ddof=1)) if len(values) > 1 else 0.0, "n": len(values)}
    return out


def write_table_and_figures(options, results, session):
    """table4.json/.md over the finished runs, and Figure 3 from the first seed's histories; returns the
    number of finished runs."""
    runs = finished_runs(options)
    evaluated = evaluate_runs(options, runs, session)
    table = {split: {column: {method: aggregate(per_seed) for method, per_seed in methods.items()}
                     for column, methods in columns.items()} for split, columns in evaluated.items()}
    training, histories = {}, {}
    for (seed, variant, column), folder in sorted(runs.items()):
        report, history = load_run(folder)
        training[f"{variant} {column} seed {seed}"] = {
            "variant": variant, "column": column, "seed": seed, "episodes": report["episodes"],
            "train_seconds": report["train_seconds"], "train_cpu_seconds": report["train_cpu_seconds"],
            "held_out_score": report["held_out"]["score"], "seen_score": report["training"]["score"]}
        if seed == options.seeds[0]:
            histories.setdefault(variant, {})[column] = history
    seeds = " ".join(str(s) for s in options.seeds)
    settings = (f"Preset `{options.preset}`, seeds {seeds}, epochs = {options.epoch_scale:g} x the paper's "
                f"(50 for one behaviour, 100 for both; an epoch is one iteration of Algorithm 1); "
                f"{len(runs)} of {len(options.seeds) * len(options.variants) * len(options.columns)} runs finished. "
                f"Regenerate: `nice -n 10 python -m trainer.scripts.experiments --preset {options.preset} "
                f"--epoch-scale {options.epoch_scale:g} --seeds {seeds}`.")
    aim = {column: {variant: aggregate(per_seed) for variant, per_seed in variants.items()}
           for column, variants in random_target_aim(options, runs, session).items()}
    report = {"settings": settings, "seeds": list(options.seeds), "table": table, "random_targets": aim,
              "random_target_count": RANDOM_TARGETS, "training": training}
    atomic_write_text(results / "table4.json", json.dumps(report, indent=1) + "\n")
    atomic_write_text(results / "table4.md", table4_markdown(report))
    for split in ("seen", "unseen"):
        plots.figure3(histories, results / f"figure3_{split}.png", split)
    return len(runs)


def load_trained_agent(folder, preset):
    """The torch agent of a finished run, from its checkpoint."""
    saved = checkpoint.load(folder / checkpoint.FILENAME)
    agent = RLAnimateAgent(load_preset(preset)[0], saved["arguments"]["variant"])
    agent.load_state_dict(saved["trainer"]["agent"])
    return agent


def write_length_flexibility(options, results, session):
    """Section 4.4 for the first seed's RLAnimate both-behaviour agent on the held-out clips."""
    folder = run_folder(options, options.seeds[0], "rlanimate", "both")
    if not is_finished(folder, planned_epochs(options, "both")):
        return None
    agent = load_trained_agent(folder, options.preset)
    test = scoring.select_clips(session.test_clips, "both")
    flexibility = scoring.length_flexibility(agent, session.env, test, session.train_clips, LENGTH_SCALES)
    atomic_write_text(results / "length_flexibility.json", json.dumps(flexibility, indent=2) + "\n")
    plots.length_flexibility(flexibility, results / "length_flexibility.png", metrics.ARTEFACT_THRESHOLD)
    return flexibility
