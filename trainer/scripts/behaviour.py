"""Behaviour metrics of RLAnimate and the baselines on the sample library's held-out requests:
docs/results/behaviour.{json,md}, the held-out waves' and points' hand paths (docs/results/behaviour_wave_paths.png,
behaviour_point_paths.png) and, when the library has guide and raise-hand clips, theirs (behaviour_guide_paths.png,
behaviour_raise_hand_paths.png).

    nice -n 10 python -m trainer.scripts.behaviour [--agent PATH] [--clips MANIFEST] [--results DIR]
                                                   [--targets 100] [--seeds 1 2 3 4]
"""
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from rlanimate_addon.core import behaviours, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io.clip_session import LibrarySession
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.blender_io.rig_session import new_empty_scene
from trainer.evaluation import behaviour
from trainer.evaluation.baselines import AgentMethod, ClassMean, NearestClip, NoMotion, mean_start_pose
from trainer.paths import DEFAULT_MANIFEST, INSTALLED_AGENT, RESULTS_DIR, shown
from trainer.reporting.behaviour_report import write_behaviour
from trainer.reporting.plots import gesture_hand_paths, wave_hand_paths
from trainer.scripts import cli
from trainer.scripts.cli import run_main

WAVE_PATHS = "behaviour_wave_paths.png"
POINT_PATHS = "behaviour_point_paths.png"
#: The hand-path figure of the held-out requests of the behaviours that present and that raise.
HELD_PATHS = {behaviours.PRESENTS: "behaviour_guide_paths.png", behaviours.RAISES: "behaviour_raise_hand_paths.png"}


@dataclass(frozen=True)
class BehaviourSettings:
    """What the behaviour metrics measure, and where they are written."""
    agent: str = str(INSTALLED_AGENT)  # exported RLAnimate agent (.npz)
    clips: str = str(DEFAULT_MANIFEST)  # clip library: a manifest.json or the folder that holds one
    results: str = str(RESULTS_DIR)  # where behaviour.json and .md and the hand-path figures go
    targets: int = 100  # random unseen pointing targets per arm
    seeds: tuple[int, ...] = (1, 2, 3, 4)  # variation seeds: at least two, none of them 0
    target_seed: int = behaviour.RANDOM_TARGET_SEED  # generator seed of the random targets (another: other targets)

    def __post_init__(self) -> None:
        if len(set(self.seeds)) < 2 or 0 in self.seeds:
            raise RLAnimateError("--seeds needs at least two different seeds, none of them 0 (seed 0 is the "
                                 "deterministic answer, always measured): for example --seeds 1 2 3 4.")


def parse_settings(argv: Sequence[str] | None = None) -> BehaviourSettings:
    """BehaviourSettings from the command line."""
    return cli.parse_settings(BehaviourSettings, argv, prog="python -m trainer.scripts.behaviour", doc=__doc__)


def behaviour_report(settings: BehaviourSettings) -> dict:
    """The report behaviour.json holds; also draws the hand-path figures into settings.results."""
    session = LibrarySession(settings.clips)
    train, test = session.train_clips, session.test_clips
    agent = AgentMethod(settings.agent)
    methods = {"rlanimate": agent, "no_motion": NoMotion(mean_start_pose(train)), "class_mean": ClassMean(train),
               "nearest_clip": NearestClip(train), "procedural_ik": ProceduralIK(mean_start_pose(train))}
    lengths = behaviour.class_lengths(train)
    waves = [c for c in test if c.declared.oscillates]
    points = [c for c in test if c.declared.aims]
    held = [c for c in test if c.declared.does in HELD_PATHS]
    sets, clips = _request_sets(methods, session, lengths, waves, points, held)
    measured = _agent_measures(agent, session, lengths, settings, waves + points)
    figures = _figures(methods, session, settings, waves, points, held)
    further = _further_sweeps(agent, session, lengths, settings)
    return {"description": _description(settings, agent, lengths, len(test)), "class_lengths": lengths,
            "sets": sets, "agent": {**measured[0], **further, **measured[1]}, "figures": figures, "clips": clips}


def _request_sets(methods, session, lengths, waves, points, held):
    """({set: {method: summary}}, {method: request rows}) of every method's answers to the held-out requests: the
    waves and points (and the points with Exact Aim), then those of the behaviours that present and that raise."""
    sets, clips = {"wave": {}, "point": {}, "point_exact_aim": {}}, {}
    for name, method in methods.items():
        rows = behaviour.request_rows(method, waves + points, session.references, session.describe, lengths)
        aimed = behaviour.request_rows(method, points, session.references, session.describe, lengths, exact_aim=True)
        summary, summary_aimed = behaviour.summarise(rows), behaviour.summarise(aimed)
        sets["wave"][name], sets["point"][name] = summary["wave"], summary["point"]
        sets["point_exact_aim"][name] = summary_aimed["point"]
        clips[name] = rows
    for name, method in methods.items():
        if held and name != "procedural_ik":  # the procedural baseline knows point and wave only
            rows = behaviour.request_rows(method, held, session.references, session.describe, lengths)
            for key, summary in behaviour.summarise(rows).items():
                sets.setdefault(key, {})[name] = summary
            clips[name] += rows
    return sets, clips


def _agent_measures(agent, session, lengths, settings, requests):
    """({its own aim at random targets, its waves over exaggerations}, {its seeds' answers and their spread})."""
    own, exact = (behaviour.random_target_sweeps(agent, lengths[behaviours.POINT], session.describe, settings.targets,
                                                 exact_aim=exact_aim, seed=settings.target_seed)
                  for exact_aim in (False, True))
    seeded = {seed: behaviour.summarise(behaviour.request_rows(agent, requests, session.references,
                                                               session.describe, lengths, seed=seed))
              for seed in settings.seeds}
    varied = behaviour.seed_variation(agent, requests, session.describe, settings.seeds)
    sweeps = {arm.lower(): behaviour.exaggeration_sweep(agent, arm, lengths[behaviours.WAVE], session.describe)
              for arm in ("LEFT", "RIGHT")}
    variation = {"seeds": list(settings.seeds), "requests": len(varied),
                 "deterministic": sum(r["deterministic"] for r in varied),
                 **{name: _spread([r["variation"] for r in varied if r["behaviour"] == name])
                    for name in ("wave", "point")}, "clips": varied}
    return ({"targets_per_arm": settings.targets,
             "random_targets": {arm: {"own": own[arm], "exact": exact[arm]} for arm in own},
             "exaggeration_sweep": sweeps},
            {"seeded": {str(seed): summary for seed, summary in seeded.items()}, "variation": variation})


def _further_sweeps(agent, session, lengths, settings):
    """The agent's guides at random targets and raised hands over exaggerations, where the library trains them."""
    trained = {c.declared.does: c.behaviour for c in session.train_clips}
    extra = {}
    if behaviours.PRESENTS in trained:
        extra["guide_targets"] = behaviour.guide_sweeps(agent, lengths[trained[behaviours.PRESENTS]],
                                                        session.describe, settings.targets, seed=settings.target_seed)
    if behaviours.RAISES in trained:
        extra["raise_sweep"] = {arm.lower(): behaviour.raise_sweep(agent, arm, lengths[trained[behaviours.RAISES]],
                                                                   session.describe) for arm in ("LEFT", "RIGHT")}
    return extra


def _figures(methods, session, settings, waves, points, held):
    """{figure: what it shows} of the hand-path figures drawn into settings.results."""
    results = Path(settings.results)
    results.mkdir(parents=True, exist_ok=True)
    wave_hand_paths([_wave_panel(clip, session, methods, settings.seeds) for clip in waves], results / WAVE_PATHS)
    figures = {f"docs/results/{WAVE_PATHS}": "the held-out waves' wrist, reference against RLAnimate "
                                             "(deterministic and one seed) and the class mean"}
    gesture_hand_paths([_held_panel(clip, session, methods) for clip in points], results / POINT_PATHS)
    figures[f"docs/results/{POINT_PATHS}"] = ("the held-out points' wrist, reference against RLAnimate (its own aim) "
                                              "and the class mean")
    for does, figure in HELD_PATHS.items():
        requests = [c for c in held if c.declared.does == does]
        if requests:
            gesture_hand_paths([_held_panel(clip, session, methods) for clip in requests], results / figure)
            figures[f"docs/results/{figure}"] = (f"the held-out {behaviours.key(requests[0].behaviour)} requests' "
                                                 "wrist, reference against RLAnimate and the class mean")
    return figures


def _description(settings, agent, lengths, request_count):
    """The report's first paragraph: what was measured, with what agent, and the command that regenerates it."""
    training = agent.agent.metadata.get("training", {})
    provenance = "untrained" if training.get("untrained") else ", ".join(
        f"{k} {training[k]}" for k in ("behaviour", "variant", "preset", "epochs", "episodes") if k in training)
    seed_words = " ".join(str(s) for s in settings.seeds)
    return (f"The {request_count} held-out requests of the sample library (sample_rigs/clips), each answered at its "
            f"clip's own length (score, smoothness, behaviour measures) and at the class-average length "
            f"({lengths[behaviours.POINT]} frames for point, {lengths[behaviours.WAVE]} for wave: the time-scaled and "
            f"the DTW scores). RLAnimate: `{shown(settings.agent)}` ({provenance}), deterministic rollouts of the "
            f"numpy runtime, FK by Blender. Regenerate: `nice -n 10 python -m trainer.scripts.behaviour --agent "
            f"{shown(settings.agent)} --targets {settings.targets} --seeds {seed_words}"
            + ("" if settings.target_seed == behaviour.RANDOM_TARGET_SEED
               else f" --target-seed {settings.target_seed}") + "`.")


def _wave_panel(clip, session, methods, seeds):
    """(title, arm, {label: positions}) of one held-out wave for wave_hand_paths: the reference, RLAnimate
    (deterministic and the first seed's) and the class mean."""
    reference = spaces.description_joint_positions(session.references.get(clip)[0])
    answers = {label: spaces.description_joint_positions(session.describe(methods[key].generate(
        clip.behaviour, clip.arm, clip.attributes, len(clip.rotvecs))))
        for key, label in (("rlanimate", "RLAnimate"), ("class_mean", "class mean"))}
    if seeds:
        answers[f"RLAnimate seed {seeds[0]}"] = spaces.description_joint_positions(session.describe(
            methods["rlanimate"].generate(clip.behaviour, clip.arm, clip.attributes, len(clip.rotvecs),
                                          seed=seeds[0])))
    return (f"{clip.name} (e = {float(np.ravel(clip.attributes)[0]):.2f})", clip.arm.upper(),
            {"reference": reference, **answers})


def _held_panel(clip, session, methods):
    """(title, arm, {label: positions}, target) of one point, guide or raise-hand request for gesture_hand_paths."""
    reference = spaces.description_joint_positions(session.references.get(clip)[0])
    answers = {label: spaces.description_joint_positions(session.describe(methods[key].generate(
        clip.behaviour, clip.arm, clip.attributes, len(clip.rotvecs))))
        for key, label in (("rlanimate", "RLAnimate"), ("class_mean", "class mean"))}
    label = (f"e = {float(np.ravel(clip.attributes)[0]):.2f}" if clip.declared.kind == behaviours.INTENSITY
             else f"target {np.round(clip.target, 1).tolist()}")
    return f"{clip.name} ({label})", clip.arm.upper(), {"reference": reference, **answers}, behaviour.clip_target(clip)


def _spread(values):
    return {"median": float(np.median(values)), "min": float(np.min(values)), "max": float(np.max(values))}


def main(argv=None):
    settings = parse_settings(argv)
    torch.set_num_threads(1)
    new_empty_scene()
    report = behaviour_report(settings)
    write_behaviour(settings.results, report)
    print((Path(settings.results) / "behaviour.md").read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main))
