"""Behaviour metrics of RLAnimate and the baselines on the sample library's held-out requests:
docs/results/behaviour.{json,md}, the held-out waves' and points' hand paths (docs/results/behaviour_wave_paths.png,
behaviour_point_paths.png) and, when the library has guide and raise-hand clips, theirs (behaviour_guide_paths.png,
behaviour_raise_hand_paths.png).

    nice -n 10 python -m trainer.scripts.behaviour [--agent PATH] [--clips MANIFEST] [--results DIR]
                                                   [--targets 100] [--seeds 1 2 3 4]
"""
import argparse
from pathlib import Path

import numpy as np
import torch

from rlanimate_addon.core import behaviours, spaces
from trainer.blender_io.clip_session import LibrarySession
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.blender_io.rig_session import new_empty_scene
from trainer.evaluation import behaviour
from trainer.evaluation.baselines import AgentMethod, ClassMean, NearestClip, NoMotion, mean_start_pose
from trainer.motion.synthesis import GUIDE, RAISE_HAND
from trainer.paths import DEFAULT_MANIFEST, INSTALLED_AGENT, RESULTS_DIR, shown
from trainer.reporting.behaviour_report import write_behaviour
from trainer.reporting.plots import gesture_hand_paths, wave_hand_paths
from trainer.scripts.cli import run_main, script_args

WAVE_PATHS = "behaviour_wave_paths.png"
POINT_PATHS = "behaviour_point_paths.png"
#: The hand-path figure of each further behaviour's held-out requests.
HELD_PATHS = {GUIDE: "behaviour_guide_paths.png", RAISE_HAND: "behaviour_raise_hand_paths.png"}


def behaviour_report(agent_path, manifest, target_count, seeds, results_dir, target_seed=behaviour.RANDOM_TARGET_SEED):
    """The report behaviour.json holds; also draws the hand-path figure into results_dir."""
    session = LibrarySession(manifest)
    train, test = session.train_clips, session.test_clips
    agent = AgentMethod(agent_path)
    methods = {"rlanimate": agent, "no_motion": NoMotion(mean_start_pose(train)), "class_mean": ClassMean(train),
               "nearest_clip": NearestClip(train), "procedural_ik": ProceduralIK(mean_start_pose(train))}

    lengths = behaviour.class_lengths(train)
    waves = [c for c in test if c.behaviour == behaviours.WAVE]
    points = [c for c in test if c.behaviour == behaviours.POINT]
    sets, clips = {"wave": {}, "point": {}, "point_exact_aim": {}}, {}
    for name, method in methods.items():
        rows = behaviour.request_rows(method, waves + points, session.references, session.describe, lengths)
        aimed = behaviour.request_rows(method, points, session.references, session.describe, lengths, exact_aim=True)
        summary, summary_aimed = behaviour.summarise(rows), behaviour.summarise(aimed)
        sets["wave"][name], sets["point"][name] = summary["wave"], summary["point"]
        sets["point_exact_aim"][name] = summary_aimed["point"]
        clips[name] = rows
    held = [c for c in test if c.behaviour in HELD_PATHS]
    for name, method in methods.items():
        if held and name != "procedural_ik":  # the procedural baseline knows point and wave only
            rows = behaviour.request_rows(method, held, session.references, session.describe, lengths)
            for key, summary in behaviour.summarise(rows).items():
                sets.setdefault(key, {})[name] = summary
            clips[name] += rows

    own, exact = (behaviour.random_target_sweeps(agent, lengths[behaviours.POINT], session.describe, target_count,
                                                 exact_aim=exact_aim, seed=target_seed) for exact_aim in (False, True))
    random_targets = {arm: {"own": own[arm], "exact": exact[arm]} for arm in own}
    sweeps = {arm.lower(): behaviour.exaggeration_sweep(agent, arm, lengths[behaviours.WAVE], session.describe)
              for arm in ("LEFT", "RIGHT")}
    seeded = {seed: behaviour.summarise(behaviour.request_rows(agent, waves + points, session.references,
                                                               session.describe, lengths, seed=seed))
              for seed in seeds}
    varied = behaviour.seed_variation(agent, waves + points, session.describe, seeds)

    panels = []
    for clip in waves:
        reference = spaces.description_joint_positions(session.references.get(clip)[0])
        answers = {label: spaces.description_joint_positions(session.describe(methods[key].generate(
            behaviours.WAVE, clip.arm, clip.attributes, len(clip.rotvecs))))
            for key, label in (("rlanimate", "RLAnimate"), ("class_mean", "class mean"))}
        if seeds:
            answers[f"RLAnimate seed {seeds[0]}"] = spaces.description_joint_positions(session.describe(agent.generate(
                behaviours.WAVE, clip.arm, clip.attributes, len(clip.rotvecs), seed=seeds[0])))
        panels.append((f"{clip.name} (e = {float(np.ravel(clip.attributes)[0]):.2f})", clip.arm.upper(),
                       {"reference": reference, **answers}))
    Path(results_dir).mkdir(parents=True, exist_ok=True)
    wave_hand_paths(panels, Path(results_dir) / WAVE_PATHS)
    figures = {f"docs/results/{WAVE_PATHS}": "the held-out waves' wrist, reference against RLAnimate "
                                             "(deterministic and one seed) and the class mean"}
    gesture_hand_paths([_held_panel(clip, session, methods) for clip in points], Path(results_dir) / POINT_PATHS)
    figures[f"docs/results/{POINT_PATHS}"] = ("the held-out points' wrist, reference against RLAnimate (its own aim) "
                                              "and the class mean")
    for behaviour_id, figure in HELD_PATHS.items():
        requests = [c for c in held if c.behaviour == behaviour_id]
        if requests:
            gesture_hand_paths([_held_panel(clip, session, methods) for clip in requests], Path(results_dir) / figure)
            figures[f"docs/results/{figure}"] = (f"the held-out {behaviours.key(behaviour_id)} requests' wrist, "
                                                 "reference against RLAnimate and the class mean")
    extra = {}
    if any(c.behaviour == GUIDE for c in train):
        extra["guide_targets"] = behaviour.guide_sweeps(agent, lengths[GUIDE], session.describe, target_count,
                                                        seed=target_seed)
    if any(c.behaviour == RAISE_HAND for c in train):
        extra["raise_sweep"] = {arm.lower(): behaviour.raise_sweep(agent, arm, lengths[RAISE_HAND], session.describe)
                                for arm in ("LEFT", "RIGHT")}

    training = agent.agent.metadata.get("training", {})
    provenance = "untrained" if training.get("untrained") else ", ".join(
        f"{k} {training[k]}" for k in ("behaviour", "variant", "preset", "epochs", "episodes") if k in training)
    seed_words = " ".join(str(s) for s in seeds)
    description = (f"The {len(test)} held-out requests of the sample library (sample_rigs/clips), each answered at its "
                   f"clip's own length (score, smoothness, behaviour measures) and at the class-average length "
                   f"({lengths['POINT']} frames for point, {lengths['WAVE']} for wave: the time-scaled and the DTW "
                   f"scores). RLAnimate: `{shown(agent_path)}` ({provenance}), deterministic rollouts of the numpy "
                   f"runtime, FK by Blender. Regenerate: `nice -n 10 python -m trainer.scripts.behaviour --agent "
                   f"{shown(agent_path)} --targets {target_count} --seeds {seed_words}"
                   + ("" if target_seed == behaviour.RANDOM_TARGET_SEED else f" --target-seed {target_seed}") + "`.")
    return {"description": description, "class_lengths": lengths, "sets": sets,
            "agent": {"targets_per_arm": target_count, "random_targets": random_targets,
                      "exaggeration_sweep": sweeps, **extra,
                      "seeded": {str(seed): summary for seed, summary in seeded.items()},
                      "variation": {"seeds": list(seeds), "requests": len(varied),
                                    "deterministic": sum(r["deterministic"] for r in varied),
                                    **{name: _spread([r["variation"] for r in varied if r["behaviour"] == name])
                                       for name in ("wave", "point")},
                                    "clips": varied}},
            "figures": figures, "clips": clips}


def _held_panel(clip, session, methods):
    """(title, arm, {label: positions}, target) of one point, guide or raise-hand request for gesture_hand_paths."""
    reference = spaces.description_joint_positions(session.references.get(clip)[0])
    answers = {label: spaces.description_joint_positions(session.describe(methods[key].generate(
        clip.behaviour, clip.arm, clip.attributes, len(clip.rotvecs))))
        for key, label in (("rlanimate", "RLAnimate"), ("class_mean", "class mean"))}
    label = (f"e = {float(np.ravel(clip.attributes)[0]):.2f}" if clip.behaviour == RAISE_HAND
             else f"target {np.round(clip.target, 1).tolist()}")
    return f"{clip.name} ({label})", clip.arm.upper(), {"reference": reference, **answers}, behaviour.clip_target(clip)


def _spread(values):
    return {"median": float(np.median(values)), "min": float(np.min(values)), "max": float(np.max(values))}


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m trainer.scripts.behaviour", description=__doc__.split("\n\n")[0])
    parser.add_argument("--agent", default=str(INSTALLED_AGENT), help="exported RLAnimate agent (.npz)")
    parser.add_argument("--clips", default=str(DEFAULT_MANIFEST))
    parser.add_argument("--results", default=str(RESULTS_DIR))
    parser.add_argument("--targets", type=int, default=100, help="random unseen pointing targets per arm")
    parser.add_argument("--seeds", type=int, nargs="*", default=[1, 2, 3, 4], help="variation seeds (not 0)")
    parser.add_argument("--target-seed", type=int, default=behaviour.RANDOM_TARGET_SEED,
                        help="generator seed of the random targets (another seed: other targets)")
    options = parser.parse_args(script_args(argv))
    if len(set(options.seeds)) < 2 or 0 in options.seeds:
        parser.error("--seeds needs at least two different seeds, none of them 0 (seed 0 is the deterministic "
                     "answer, always measured): for example --seeds 1 2 3 4.")
    torch.set_num_threads(1)
    new_empty_scene()
    report = behaviour_report(options.agent, options.clips, options.targets, tuple(options.seeds), options.results,
                              options.target_seed)
    write_behaviour(options.results, report)
    print((Path(options.results) / "behaviour.md").read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main))
