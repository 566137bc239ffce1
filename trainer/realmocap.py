"""Learn from real motion capture (Bandai Namco Research, CC BY-NC 4.0) and compare with the baselines.

    nice -n 15 python -m trainer.realmocap [--epochs 50] [--point-agent PATH]   (finished runs are reused)

The clips are read from ../shared/realmocap/ beside the repository (never copied into it; see
docs/REALMOCAP.md). Each BVH goes through trainer.clip_import (Blender's BVH importer and the
world-direction retarget onto the canonical rig); the capture has no fingers, so a relaxed open hand
(RELAXED_HAND) is put on, and labels come from the motion (trainer.autolabel).

Experiments, each trained with train.run on a session of real clips (runs/realmocap/<name>/):
    wave      wave agent on takes 001-008 of the 7 styles x 2 arms (112 clips), tested on takes
              009-010 (28) and on the 14 goodbye waves of dataset 1 (other actor takes, other styles)
    holdout   the same on all takes of 5 styles (100 clips), tested on the 2 unseen styles (40 clips)
    guide     the right-arm directing gestures as pointing: the pointing agent is given the direction
              in which the actor held the arm, and we report the angle between the generated and the
              real forearm (elbow -> wrist) at each one's hold
Both baselines (trainer.baselines) answer the same requests. Writes docs/results/realmocap.json and
.md, the real-data section of docs/results/baselines.json and .md, and
docs/results/realmocap_frames.png (generated and real frames side by side).
"""
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
if str(REPO_ROOT) not in sys.path:
    sys.path.insert(0, str(REPO_ROOT))

import argparse  # noqa: E402
import json  # noqa: E402
import re  # noqa: E402
from dataclasses import replace  # noqa: E402

import numpy as np  # noqa: E402

from rlanimate_addon.core import skeleton  # noqa: E402
from rlanimate_addon.core.errors import RLAnimateError  # noqa: E402
from trainer import autolabel, baselines  # noqa: E402

REALMOCAP_DIR = REPO_ROOT.parent / "shared" / "realmocap"
RUNS_DIR = REPO_ROOT / "runs" / "realmocap"
RESULTS_DIR = REPO_ROOT / "docs" / "results"
STYLES = ("active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful")
TRAIN_TAKES = tuple(f"{k:03d}" for k in range(1, 9))
TEST_TAKES = ("009", "010")
#: Styles the hold-out agent never sees: the two whose labels fall between the trained ones
#: (exaggeration ~0.3 and ~0.55 against 0.1 feminine and 0.75-1 for the rest), as the paper's unseen
#: waves are exaggerations between the training ones.
HOLDOUT_STYLES = ("elderly", "exhausted")
#: Relaxed open hand for a capture without fingers: {finger bone: local rotation vector (rad)}.
#: Fingers curl about their local X axis (negative: towards the palm), a little more towards the
#: pinky; the thumb rests slightly in. Index1 is an action joint; the rest only show in pictures.
RELAXED_HAND = {"Index": -0.12, "Middle": -0.18, "Ring": -0.24, "Pinky": -0.3}
RELAXED_THUMB = (0.0, 0.0, 0.15)

_NAME = re.compile(r"dataset-(?P<dataset>\d)_(?P<content>[a-z]+)(?:-(?P<side>left|right)-hand)?"
                   r"_(?P<style>[a-z-]+)_(?P<take>\d{3})$")


def require_realmocap(root=REALMOCAP_DIR):
    """The real-mocap folder, or RLAnimateError saying where it is expected."""
    root = Path(root)
    if not (root / "wave").is_dir():
        raise RLAnimateError(f"The real motion capture is not at {root}: put the Bandai Namco clips "
                             "(wave/, bye/, guide/) there, as ../shared/realmocap/README.md describes.")
    return root


def parse_name(path):
    """{'content', 'arm' (LEFT/RIGHT or None), 'style', 'take'} of a real-mocap file name."""
    match = _NAME.match(Path(path).stem)
    if match is None:
        raise RLAnimateError(f"{path}: not a Bandai Namco file name (dataset-N_content_style_take.bvh).")
    side = match["side"]
    return {"content": match["content"], "arm": side.upper() if side else None,
            "style": match["style"], "take": match["take"]}


def relaxed_hand(clip):
    """`clip` with a relaxed open hand on both sides: Index1 in its rotvecs, the other fingers in .fingers."""
    rotvecs = np.array(clip.rotvecs, dtype=np.float64)
    frames = len(rotvecs)
    fingers = dict(clip.fingers)
    for side in ("Left", "Right"):
        rotvecs[:, skeleton.ACTION_JOINTS.index(side + "HandIndex1")] = (RELAXED_HAND["Index"], 0.0, 0.0)
        for finger, curl in RELAXED_HAND.items():
            for k in (1, 2, 3):
                name = f"{side}Hand{finger}{k}"
                if name not in skeleton.ACTION_JOINTS:
                    fingers[name] = np.tile((curl, 0.0, 0.0), (frames, 1))
        fingers[f"{side}HandThumb1"] = np.tile(RELAXED_THUMB, (frames, 1))
    return replace(clip, rotvecs=rotvecs, fingers=fingers)


def import_real_clip(path, cache_dir=RUNS_DIR / "import_cache"):
    """A real clip on the canonical rig with a relaxed hand and labels derived from its motion.

    wave/ and bye/ clips are WAVE (arm and exaggeration from autolabel.label_wave); guide/ clips are
    POINT (arm and held direction from autolabel.label_point). `.style` and `.take` come from the name.
    """
    from trainer import clip_import
    info = parse_name(path)
    clip = relaxed_hand(clip_import.import_clip(path, cache_dir=cache_dir))
    autolabel.label_clip(clip, "POINT" if info["content"] == "guide" else "WAVE")
    clip.content, clip.style, clip.take, clip.named_arm = info["content"], info["style"], info["take"], info["arm"]
    return clip


def load_folder(folder, root=REALMOCAP_DIR, cache_dir=RUNS_DIR / "import_cache"):
    """Every clip of root/folder ('wave', 'bye' or 'guide'), sorted by name."""
    paths = sorted((require_realmocap(root) / folder).glob("*.bvh"))
    return [import_real_clip(p, cache_dir) for p in paths]


def wave_split(clips):
    """(train, test): takes 001-008 and 009-010 of the one-arm waves."""
    return [c for c in clips if c.take in TRAIN_TAKES], [c for c in clips if c.take in TEST_TAKES]


def style_holdout_split(clips, held_out=HOLDOUT_STYLES):
    """(train, test): every take of the other styles, and of the held-out ones."""
    return [c for c in clips if c.style not in held_out], [c for c in clips if c.style in held_out]


class RealSession:
    """What train.run needs (env, references, train_clips, test_clips), over real clips."""

    def __init__(self, env, references, train_clips, test_clips):
        self.env, self.references = env, references
        for split, clips in (("train", train_clips), ("test", test_clips)):
            for clip in clips:
                clip.split = split
        self.train_clips, self.test_clips = list(train_clips), list(test_clips)


def forearm_direction(bone_heads, bone_names, arm):
    """(F, 3) unit elbow -> wrist vectors from FKResult.bone_heads."""
    side = skeleton.ARM_PREFIX[arm]
    elbow = bone_heads[:, bone_names.index(side + "ForeArm")]
    wrist = bone_heads[:, bone_names.index(side + "Hand")]
    vectors = wrist - elbow
    return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


def angle_degrees(a, b):
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0))))


def guide_angles(method, clips, env):
    """Per guide clip: the angle (deg) between generated and real forearm directions at their holds."""
    rows = []
    motions = baselines.generate_for(method, clips)
    for clip, motion in zip(clips, motions):
        real = env.evaluate(clip.rotvecs)
        generated = env.evaluate(motion)
        hold = autolabel.label_point(motion, clip.arm).hold_frame
        real_forearm = forearm_direction(real.bone_heads, env.bone_names, clip.arm)[clip.label.hold_frame]
        generated_forearm = forearm_direction(generated.bone_heads, env.bone_names, clip.arm)[hold]
        rows.append({"name": clip.name, "style": clip.style, "arm": clip.arm,
                     "direction": [round(float(v), 4) for v in clip.attributes],
                     "forearm_angle_deg": angle_degrees(real_forearm, generated_forearm)})
    return {"mean_forearm_angle_deg": float(np.mean([r["forearm_angle_deg"] for r in rows])),
            "median_forearm_angle_deg": float(np.median([r["forearm_angle_deg"] for r in rows])), "clips": rows}


def train_agent(session, name, behaviour, epochs, preset, seed, runs=RUNS_DIR):
    """train.run on `session` into runs/<name>/ (resumed when a checkpoint is there); (report, method)."""
    from trainer import checkpoint, train
    output = Path(runs) / name
    argv = ["--behaviour", behaviour, "--epochs", str(epochs), "--preset", preset, "--seed", str(seed),
            "--output", str(output), "--clips", f"realmocap:{name}", "--eval-every", "0", "--quiet"]
    if (output / checkpoint.FILENAME).is_file():
        argv.append("--resume")
    report, trainer = train.run(train.build_parser().parse_args(argv), session)
    return report, baselines.TrainedAgentMethod(trainer, output / "agent.npz")


def compare(methods, clips, env, references):
    """{method: evaluate_motions result} on `clips`; for waves also `label_error`, the mean
    |autolabel exaggeration of the generated wave - requested exaggeration| (does it portray the label?)."""
    results = {}
    for name, method in methods.items():
        motions = baselines.generate_for(method, clips)
        result = baselines.evaluate_motions(env, motions, clips, references)
        if all(c.behaviour == "WAVE" for c in clips):
            result["label_error"] = float(np.mean([abs(autolabel.label_wave(m).exaggeration - c.exaggeration)
                                                   for m, c in zip(motions, clips)]))
        results[name] = result
    return results


def label_table(clips):
    """{style: {arm: mean exaggeration}} and per-style elevation/stroke means, for the report."""
    table = {}
    for clip in clips:
        entry = table.setdefault(clip.style, {"exaggeration": [], "elevation": [], "stroke": [], "arm_correct": []})
        entry["exaggeration"].append(clip.exaggeration)
        entry["elevation"].append(clip.label.elevation)
        entry["stroke"].append(clip.label.stroke)
        entry["arm_correct"].append(clip.named_arm is None or clip.named_arm == clip.arm)
    return {style: {"clips": len(v["exaggeration"]), "exaggeration": float(np.mean(v["exaggeration"])),
                    "exaggeration_sd": float(np.std(v["exaggeration"])), "elevation_deg": float(np.mean(v["elevation"])),
                    "stroke_arm_lengths": float(np.mean(v["stroke"])), "arm_correct": int(np.sum(v["arm_correct"]))}
            for style, v in sorted(table.items(), key=lambda item: np.mean(item[1]["exaggeration"]))}


def point_agent_and_library(point_agent, runs, epochs, seed):
    """(AgentMethod, sample-library point training clips) for the guide experiment.

    `point_agent` None: the add-on's installed default agent when it is trained, else a point agent
    trained here on the sample library (runs/realmocap/sample_point/)."""
    from trainer import train
    library = train.Session(train.DEFAULT_MANIFEST)
    clips = [c for c in library.train_clips if c.behaviour == "POINT"]
    if point_agent is None:
        try:
            installed = baselines.AgentMethod(train.INSTALLED_AGENT)
            training = installed.agent.metadata.get("training", {})
            if not training.get("untrained") and training.get("behaviour") in ("point", "both"):
                return installed, clips
        except RLAnimateError as error:
            print(f"realmocap: not using the installed agent: {error}", file=sys.stderr)
        return train_agent(library, "sample_point", "point", epochs, "default", seed, runs)[1], clips
    return baselines.AgentMethod(point_agent), clips


def frames_figure(env, rows, path, times=(0.15, 0.35, 0.5, 0.65, 0.85)):
    """Front views of real (grey) and generated (red) frames side by side; one row per (title, real
    (F, 15, 3), generated (F, 15, 3)) in `rows`, one column per fraction of the clip in `times`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = env.bone_names
    links = [(names.index(b.name), names.index(b.parent)) for b in skeleton.BONES
             if b.parent and b.name in names and b.parent in names
             and not any(part in b.name for part in ("Eye", "Thumb", "Middle", "Ring", "Pinky", "Toe", "_End"))]
    figure, axes = plt.subplots(len(rows), len(times), figsize=(2.2 * len(times), 2.6 * len(rows)), squeeze=False)
    for r, (title, real, generated) in enumerate(rows):
        heads = {"real": env.evaluate(real).bone_heads, "generated": env.evaluate(generated).bone_heads}
        for c, fraction in enumerate(times):
            ax = axes[r, c]
            frame = int(round(fraction * (len(real) - 1)))
            for key, offset, colour in (("real", -0.45, "0.35"), ("generated", 0.45, "tab:red")):
                # The character faces -Y: seen from the front, its left (+X) is on the viewer's right.
                points = heads[key][frame]
                for child, parent in links:
                    ax.plot([points[child, 0] + offset, points[parent, 0] + offset],
                            [points[child, 2], points[parent, 2]], color=colour, lw=1.5)
            ax.set_xlim(-1.4, 1.4)
            ax.set_ylim(0.0, 2.4)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(f"t = {fraction:.2f} N", fontsize=8)
            if c == 0:
                ax.set_ylabel(title, fontsize=7)
    figure.suptitle("Real capture, retargeted (grey, left) and RLAnimate (red, right), front view", fontsize=9)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def _summary(result):
    return {"clips": len(result["clips"]),
            **{key: result[key] for key in ("score", "smoothness", "label_error") if key in result}}


def run_experiments(options):
    """All experiments; returns the realmocap results dict (also written to options.results)."""
    import bpy
    import torch
    torch.set_num_threads(1)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    from trainer.algorithm import ClipReferences
    from trainer.fk_env import FKEnvironment

    root = require_realmocap(options.realmocap)
    Path(options.results).mkdir(parents=True, exist_ok=True)
    cache = Path(options.runs) / "import_cache"
    waves, byes, guides = (load_folder(f, root, cache) for f in ("wave", "bye", "guide"))
    env = FKEnvironment()
    references = ClipReferences(env)
    command = (f"nice -n 15 python -m trainer.realmocap --epochs {options.epochs} --preset {options.preset} "
               f"--seed {options.seed}")
    if options.point_agent:
        command += f" --point-agent {options.point_agent}"
    results = {"source": "Bandai Namco Research motion dataset (CC BY-NC 4.0), read from ../shared/realmocap/",
               "command": command,
               "epochs": options.epochs, "preset": options.preset, "seed": options.seed,
               "labels": {"wave": label_table(waves), "bye": label_table(byes)}}

    experiments = {"wave": wave_split(waves), "holdout": style_holdout_split(waves)}
    for name, (train_clips, test_clips) in experiments.items():
        session = RealSession(env, references, train_clips, test_clips)
        report, agent = train_agent(session, name, "wave", options.epochs, options.preset, options.seed, options.runs)
        methods = {"rlanimate": agent, "nearest_clip": baselines.NearestClip(train_clips),
                   "procedural_ik": baselines.ProceduralIK(baselines.neutral_pose(train_clips))}
        sets = {"test": test_clips} if name == "holdout" else {"test": test_clips, "bye": byes}
        entry = {"train_clips": len(train_clips), "episodes": report["episodes"],
                 "train_seconds": report["train_seconds"], "seen": _summary(report["training"])}
        if name == "holdout":
            entry["held_out_styles"] = list(HOLDOUT_STYLES)
        for set_name, clips in sets.items():
            entry[set_name] = compare(methods, clips, env, references)
        results[name] = entry
        if name == "wave":
            chosen = [min(test_clips, key=lambda c: abs(c.exaggeration - e)) for e in (0.1, 0.7, 1.0)]
            generated = baselines.generate_for(methods["rlanimate"], chosen)
            frames_figure(env, [(f"{c.style} {c.arm.lower()} {c.take}\ne = {c.exaggeration:.2f}", c.rotvecs, g)
                                for c, g in zip(chosen, generated)], Path(options.results) / "realmocap_frames.png")

    try:
        point_method, point_clips = point_agent_and_library(options.point_agent, options.runs, options.epochs,
                                                            options.seed)
    except RLAnimateError as error:  # no pointing agent and no sample library to train one on
        results["guide"] = {"skipped": str(error)}
        return results
    guide_methods = {"rlanimate": point_method, "nearest_clip": baselines.NearestClip(point_clips),
                     "procedural_ik": baselines.ProceduralIK(baselines.neutral_pose(point_clips))}
    agent_path = point_method.path.resolve()
    results["guide"] = {"point_agent": str(agent_path.relative_to(REPO_ROOT) if agent_path.is_relative_to(REPO_ROOT)
                                           else agent_path),
                        **{name: guide_angles(method, guides, env) for name, method in guide_methods.items()}}
    return results


def _method_rows(comparison):
    return {method: _summary(result) for method, result in comparison.items()}


def baseline_sets(results):
    """The real-data section of baselines.json: {set: {method: {score, smoothness, clips}}}."""
    sets = {"waves, takes 009-010 (28)": _method_rows(results["wave"]["test"]),
            "goodbye waves, dataset 1 (14)": _method_rows(results["wave"]["bye"]),
            f"waves, unseen styles {' + '.join(HOLDOUT_STYLES)} (40)": _method_rows(results["holdout"]["test"])}
    if "skipped" in results["guide"]:
        return sets
    sets["guide clips as pointing (14)"] = {
        method: {"forearm_angle_deg": entry["mean_forearm_angle_deg"]}
        for method, entry in results["guide"].items() if isinstance(entry, dict)}
    return sets


def realmocap_markdown(results):
    lines = ["# Learning from real motion capture", "",
             f"Bandai Namco Research motion dataset (CC BY-NC 4.0, Kobayashi et al. 2023), retargeted onto the "
             f"sample rig with a synthesised relaxed hand and labelled from the motion (docs/REALMOCAP.md). "
             f"Preset `{results['preset']}`, {results['epochs']} epochs, seed {results['seed']}. "
             f"Regenerate: `{results['command']}`.", "",
             "## Auto-labels per style (one-arm waves, 20 clips each)", "",
             "| style | exaggeration (mean ± sd) | elevation (deg) | stroke (arm lengths) | arm detected |",
             "|---|---|---|---|---|"]
    for style, row in results["labels"]["wave"].items():
        lines.append(f"| {style} | {row['exaggeration']:.2f} ± {row['exaggeration_sd']:.2f} | {row['elevation_deg']:.0f} | "
                     f"{row['stroke_arm_lengths']:.2f} | {row['arm_correct']}/{row['clips']} |")
    bye = results["labels"]["bye"].items()
    lines += ["", "Goodbye waves: " + ", ".join(f"{style} {row['exaggeration']:.2f}" for style, row in bye), ""]
    lines += ["## Score and smoothness", "",
              "Label error: mean |exaggeration auto-labelled from the generated wave - requested exaggeration|.", "",
              "| experiment | test set | method | score | smoothness | label error |", "|---|---|---|---|---|---|"]
    for name, label in (("wave", "wave agent, takes 001-008 (112 clips)"),
                        ("holdout", f"wave agent, 5 styles (100 clips; unseen: {', '.join(HOLDOUT_STYLES)})")):
        entry = results[name]
        for set_name in ("test", "bye"):
            for method, result in entry.get(set_name, {}).items():
                lines.append(f"| {label} | {set_name} ({len(result['clips'])}) | {baselines.METHOD_LABELS[method]} | "
                             f"{result['score']:.2f} | {result['smoothness']:.2f} | {result['label_error']:.3f} |")
        lines.append(f"| {label} | seen (10 training clips) | RLAnimate | {entry['seen']['score']:.2f} | "
                     f"{entry['seen']['smoothness']:.2f} | |")
    lines += ["", f"Training: wave agent {results['wave']['episodes']} episodes, {results['wave']['train_seconds']:.0f} s; "
              f"hold-out agent {results['holdout']['episodes']} episodes, {results['holdout']['train_seconds']:.0f} s "
              "(1 torch thread).", "",
              "## Guide clips as pointing", ""]
    if "skipped" in results["guide"]:
        return "\n".join(lines + [f"Not run: {results['guide']['skipped']}", "",
                                   "![real and generated frames](realmocap_frames.png)", ""])
    lines += [f"Pointing agent `{results['guide']['point_agent']}`, given the direction in which the actor held the arm "
              "(rest shoulder to the index base at the hold). Angle between the generated and the real forearm "
              "(elbow to wrist), each at its own hold:", "",
              "| method | mean (deg) | median (deg) |", "|---|---|---|"]
    for method, entry in results["guide"].items():
        if isinstance(entry, dict):
            lines.append(f"| {baselines.METHOD_LABELS[method]} | {entry['mean_forearm_angle_deg']:.1f} | "
                         f"{entry['median_forearm_angle_deg']:.1f} |")
    lines += ["", "![real and generated frames](realmocap_frames.png)", ""]
    return "\n".join(lines)


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m trainer.realmocap", description=__doc__.split("\n\n")[0])
    parser.add_argument("--realmocap", default=str(REALMOCAP_DIR))
    parser.add_argument("--epochs", type=int, default=50, help="iterations of Algorithm 1 per agent (paper: 50)")
    parser.add_argument("--preset", default="default")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--point-agent", default=None,
                        help="exported pointing agent (.npz) for the guide clips (default: the installed "
                             "agent when trained, else one trained here on the sample library)")
    parser.add_argument("--runs", default=str(RUNS_DIR))
    parser.add_argument("--results", default=str(RESULTS_DIR))
    return parser


def main(argv=None):
    from trainer.bpy_support import script_args
    options = build_parser().parse_args(script_args(argv))
    try:
        results = run_experiments(options)
    except RLAnimateError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    out = Path(options.results)
    (out / "realmocap.json").write_text(json.dumps(results, indent=2) + "\n")
    (out / "realmocap.md").write_text(realmocap_markdown(results))
    baselines.write_results(out, "real motion capture",
                            "Agents trained on the real waves (takes 001-008, or 5 styles); pointing agent from "
                            f"the sample library for the guide clips. Regenerate: `{results['command']}`.",
                            baseline_sets(results))
    print(realmocap_markdown(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
