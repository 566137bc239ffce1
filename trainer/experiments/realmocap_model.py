"""Which model and training settings beat lookup on real capture with the tempo asked, chosen on validation takes
that no test holds (`python -m trainer.scripts.realmocap_model`).

The validation experiments are the length search's (trainer/experiments/realmocap_length.py): takes 007-008 stand
for the test takes 009-010, style normal for the unseen styles. Each preset of `presets` (trainer/agent/config.py:
`end_chunks`, the real-capture recipe, and the options tried against it) trains one agent per experiment and seed
as the real-capture experiments train it (`real_run`; reused from runs/realmocap[_seed<N>]/ when finished), scored
through its exported agent on the validation takes with both requests, beside nearest-clip retrieval from the same
training takes: score, DTW score, per style, the takes whose smoothness is under the artefact threshold, and the
last-frame elevation error of each style (the issue's bars).
"""
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rlanimate_addon.core import metrics
from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent.config import PRESETS
from trainer.evaluation import baselines
from trainer.experiments.realmocap import (
    REQUESTS,
    RealCaptureSettings,
    RealMocapSettings,
    compare,
    real_run,
    train_real_runs,
    waves_and_env,
)
from trainer.experiments.realmocap_length import EXPERIMENTS
from trainer.motion.fk import ClipReferences
from trainer.reporting.realmocap_report import seed_summary


@dataclass(frozen=True)
class ModelSettings(RealCaptureSettings):
    """What the model search runs: the presets (the recipe first), the epochs, the seeds and the validation
    experiments."""
    # config presets to compare, the recipe first (trainer/agent/config.py)
    presets: tuple[str, ...] = ("end_chunks", "end_chunks_long", "end_chunks_smooth")
    epochs: int = 100  # iterations of Algorithm 1 per agent
    seeds: tuple[int, ...] = (0,)  # training seeds
    experiments: tuple[str, ...] = ("takes", "style")  # validation experiments: takes (007-008) and/or style (normal)

    def __post_init__(self):
        unknown = [p for p in self.presets if p not in PRESETS] + [e for e in self.experiments if e not in EXPERIMENTS]
        if unknown or not self.presets or not self.seeds or self.epochs < 1:
            raise RLAnimateError(f"Model search: unknown {', '.join(unknown) or 'settings'}; give presets of "
                                 f"{', '.join(PRESETS)}, experiments of {', '.join(EXPERIMENTS)}, seeds and epochs.")


def validation_summary(result: dict) -> dict:
    """seed_summary of a scoring result, with the issue's bars: the takes under the smoothness threshold, the least
    smoothness, and the largest of the styles' median last-frame elevation errors."""
    summary = seed_summary(result)
    smoothness = [clip["smoothness"] for clip in result["clips"]]
    summary.update(rough_takes=int(np.sum(np.array(smoothness) < metrics.ARTEFACT_THRESHOLD)),
                   smoothness_min=float(min(smoothness)),
                   worst_style_last_error=max(s["elevation_last_error"] for s in summary["by_style"].values()))
    return summary


def run_models(settings: ModelSettings) -> dict:
    """Train every (experiment, preset, seed) agent of `settings` and score it; the results dict."""
    waves, env = waves_and_env(settings.realmocap, settings.runs)
    references = ClipReferences(env)
    splits = {name: EXPERIMENTS[name][0](waves) for name in settings.experiments}
    runs = {(name, preset, seed): real_run(f"{name}_validation_{settings.epochs}", train, validation, seed,
                                           RealMocapSettings(epochs=settings.epochs, preset=preset, runs=settings.runs))
            for preset in settings.presets for seed in settings.seeds for name, (train, validation) in splits.items()}
    reports = train_real_runs(runs.values(), workers=settings.workers)
    experiments: dict[str, Any] = {}
    results = {"command": command_line(settings), "epochs": settings.epochs, "presets": list(settings.presets),
               "seeds": list(settings.seeds), "experiments": experiments}
    for name, (train, validation) in splits.items():
        retrieval = baselines.NearestClip(train)
        entry = experiments[name] = {
            "validates": EXPERIMENTS[name][1], "train_clips": len(train), "validation_clips": len(validation),
            "retrieval": {suffix or "paper": validation_summary(compare({"r": retrieval}, validation, env, references,
                                                                        with_tempo)["r"])
                          for suffix, with_tempo in REQUESTS.items()}, "presets": {}}
        for preset in settings.presets:
            entry["presets"][preset] = {}
            for seed in settings.seeds:
                run = runs[name, preset, seed]
                started = time.process_time()
                agent = baselines.AgentMethod(Path(run.settings.output) / "agent.npz")
                scored = {suffix or "paper": validation_summary(compare({"a": agent}, validation, env, references,
                                                                        with_tempo)["a"])
                          for suffix, with_tempo in REQUESTS.items()}
                entry["presets"][preset][str(seed)] = {
                    "train_cpu_seconds": reports[run.settings.output]["train_cpu_seconds"], **scored,
                    "scoring_cpu_seconds": time.process_time() - started}
    return results


def command_line(settings: ModelSettings) -> str:
    """The command that regenerates these results."""
    return (f"nice -n 15 python -m trainer.scripts.realmocap_model --presets {' '.join(settings.presets)} "
            f"--epochs {settings.epochs} --seeds {' '.join(map(str, settings.seeds))} "
            f"--experiments {' '.join(settings.experiments)}")
