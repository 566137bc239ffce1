"""Guide and goodbye takes beside the waves: one agent learns three behaviours of the real capture, compared
with nearest-clip retrieval (`python -m trainer.scripts.realmocap_gestures`). An experiment: nothing
trained here ships (the capture is CC BY-NC 4.0).

Behaviours (realmocap_takes.GESTURE_LABELS): WAVE (the one-arm waves), GUIDE ("this way", a target
behaviour: the direction the arm is held in, as autolabel reads a point) and BYE (the goodbye waves, an
intensity behaviour: the exaggeration autolabel reads from a wave). Dataset 1 has one take per style of
guide and bye, so their test is on styles: the same 4 of the 14 held out for both
(realmocap_takes.gesture_test_styles, seeded), the other 10 train. Waves split as the wave experiment
does (takes 001-008 and 021-036 train, 009-010 test; 011-020 never read).

One agent per seed (epochs from the settings) trains on every training take as a Ray task
(realmocap.train_real) into runs/realmocap/gestures/ (seed 0) or runs/realmocap_seed<N>/gestures/. The first
seed's agent gives the full tables and the figure; every seed's is scored on the held-out sets ("seeds").
Retrieval answers the same requests from the same training clips. Each test set is scored as realmocap.md
scores the waves (score, DTW score), with the behaviour's metrics: a guide take with the guide metrics
towards a target along its held direction (realmocap_takes.GUIDE_TARGET_DISTANCE), a goodbye wave with the wave
metrics (generated as BYE, measured as a wave).
"""
from dataclasses import dataclass, replace
from pathlib import Path

import torch

from rlanimate_addon.core import behaviours
from trainer.blender_io.fk_env import FKEnvironment
from trainer.blender_io.rig_session import blender_output, new_empty_scene
from trainer.evaluation import baselines, scoring
from trainer.experiments.options import require_values
from trainer.experiments.realmocap import RealCaptureSettings, load_folder, real_run, train_real_runs
from trainer.motion.fk import ClipReferences
from trainer.motion.realmocap_takes import (
    GESTURE_LABELS,
    gesture_split,
    gesture_test_styles,
    require_realmocap,
    wave_split,
)
from trainer.reporting.realmocap_gestures_report import held_out_summary

NAME = "gestures"
BYE = GESTURE_LABELS["bye"].name
GUIDE = GESTURE_LABELS["guide"].name


@dataclass(frozen=True)
class GestureSettings(RealCaptureSettings):
    """What the gesture experiment runs."""
    epochs: int = 50  # iterations of Algorithm 1 (paper: 50)
    preset: str = "default"  # config preset
    seeds: tuple[int, ...] = (0,)  # training seeds, one agent each; the first seed's agent gives the full tables
    import_workers: int = 1  # import the takes the cache lacks with N Blenders at once (Ray tasks)
    address: str | None = None  # join a Ray cluster: auto or ray://HOST:PORT (None: a local Ray)
    workers: int | None = 1  # training runs at a time (1: one after another; None: one per CPU)

    def __post_init__(self) -> None:
        require_values(self, "seeds")


def gesture_sets(waves, byes, guides):
    """(training clips, {test set: clips}): wave takes by wave_split, guide and bye takes by gesture_split;
    the test sets are the waves' takes 009-010, the held-out styles' guides and byes, and, to show what the
    agent learned of what it saw, the training styles' guides and byes."""
    wave_train, wave_test = wave_split(waves)
    gesture_train, gesture_test = gesture_split(byes + guides)
    sets = {"waves": wave_test}
    for behaviour in (GUIDE, BYE):
        sets[f"{behaviours.key(behaviour)}_test"] = [c for c in gesture_test if c.behaviour == behaviour]
        sets[f"{behaviours.key(behaviour)}_seen"] = [c for c in gesture_train if c.behaviour == behaviour]
    return wave_train + gesture_train, sets


def as_wave(clip):
    """A goodbye take seen as a wave, for the wave metrics (its request stays BYE)."""
    return replace(clip, behaviour=behaviours.WAVE, kind=None) if clip.behaviour == BYE else clip


def score(method, clips, env):
    """scoring.score_motions of `method`'s answers to `clips`' requests, goodbye waves measured as waves."""
    motions = baselines.generate_for(method, clips)
    measured = [as_wave(c) for c in clips]
    return scoring.score_motions(env, motions, measured, ClipReferences(env))


#: The held-out sets, scored for every seed's agent.
HELD_OUT_SETS = ("waves", "guide_test", "bye_test")


def run_experiment(settings: GestureSettings) -> tuple[dict, dict]:
    """Train (or reuse) the agents and score them and retrieval: every set for the first seed's agent, the
    held-out sets for every seed's; (results dict, {'env', 'methods', 'sets'} for the figure)."""
    torch.set_num_threads(1)
    new_empty_scene()
    root = require_realmocap(settings.realmocap)
    cache = Path(settings.runs) / "import_cache"
    with blender_output():
        waves, byes, guides = (load_folder(f, root, cache, settings.import_workers, GESTURE_LABELS)
                               for f in ("wave", "bye", "guide"))
        env = FKEnvironment()
    train, sets = gesture_sets(waves, byes, guides)
    held_out = [c for name in HELD_OUT_SETS for c in sets[name]]
    seeds = list(dict.fromkeys(settings.seeds))
    runs = [real_run(NAME, train, held_out, seed, settings, GESTURE_LABELS, behaviours.ALL) for seed in seeds]
    reports = train_real_runs(runs, settings.address, settings.workers)
    agents = [baselines.AgentMethod(Path(run.settings.output) / "agent.npz") for run in runs]
    report = reports[runs[0].settings.output]
    methods = {"rlanimate": agents[0], "nearest_clip": baselines.NearestClip(train)}
    command = (f"nice -n 15 python -m trainer.scripts.realmocap_gestures --epochs {settings.epochs} "
               f"--preset {settings.preset} --seeds {' '.join(str(seed) for seed in seeds)}")
    results = {"source": "Bandai Namco Research motion dataset (CC BY-NC 4.0), read from ../shared/realmocap/",
               "command": command, "epochs": settings.epochs, "preset": settings.preset, "seeds": seeds,
               "behaviours": {b.name: b.kind for b in GESTURE_LABELS.values()},
               "test_styles": list(gesture_test_styles()),
               "train_clips": {behaviours.key(b): sum(c.behaviour == b for c in train)
                               for b in (behaviours.WAVE, GUIDE, BYE)},
               "train_styles": sorted({c.style for c in train if c.behaviour in (GUIDE, BYE)}),
               "episodes": report["episodes"], "train_seconds": report["train_seconds"],
               "sets": {name: {"clips": [c.name for c in clips],
                               **{m: score(method, clips, env) for m, method in methods.items()}}
                        for name, clips in sets.items()}}
    results["seed_sets"] = {}
    for name in HELD_OUT_SETS:
        per_seed = {str(seeds[0]): held_out_summary(results["sets"][name]["rlanimate"])}
        per_seed.update({str(seed): held_out_summary(score(agent, sets[name], env))
                         for seed, agent in zip(seeds[1:], agents[1:], strict=True)})
        results["seed_sets"][name] = {"rlanimate": per_seed,
                                      "nearest_clip": held_out_summary(results["sets"][name]["nearest_clip"])}
    results["train_seconds_per_seed"] = {str(seed): reports[run.settings.output]["train_seconds"]
                                         for seed, run in zip(seeds, runs, strict=True)}
    return results, {"env": env, "methods": methods, "sets": sets}
