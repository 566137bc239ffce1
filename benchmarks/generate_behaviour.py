"""Generate Gesture's behaviour as an animator sees it: drive the operator on the sample character, read the
baked pose back from Blender frame by frame, and measure it with core.behaviour_metrics.

Waves: both arms, exaggerations 0.1-0.9, Variation Seeds 0 and 3: hand-up time, strokes, full cycles,
frequency, swing and smoothness; whether the swing rises with the exaggeration; how far seeds 0 and 3
lie apart. Points: random targets 1.5-4 m away (the library's ranges), both arms, Exact Aim off (the
agent's own aim) and on: the pointing angle at the hold and the lowest smoothness. The character
starts each gesture standing with its arms hanging.
Writes docs/results/generate_behaviour.md.

Run: `nice -n 10 python benchmarks/generate_behaviour.py [--targets 20] [--agent PATH]`
"""
import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402, I001  (before addon_utils, Blender's module, importable once bpy is)
import addon_utils  # noqa: E402
import numpy as np  # noqa: E402

from rlanimate_addon.core import behaviour_metrics as bm  # noqa: E402
from rlanimate_addon.core import metrics, skeleton  # noqa: E402
from rlanimate_addon.core.rotations import matrix_to_quat, rotvec_to_matrix  # noqa: E402
from trainer.blender_io import rig_session  # noqa: E402
from trainer.evaluation.behaviour import random_targets  # noqa: E402
from trainer.paths import RESULTS_DIR, SAMPLE_RIG_BLEND, shown  # noqa: E402
from trainer.reporting.tables import markdown_table  # noqa: E402

EXAGGERATIONS = (0.1, 0.3, 0.5, 0.7, 0.9)
SEEDS = (0, 3)
SPACING = 400  # frames between gestures on the one character
TARGET_SEED = 7


def stand(rig, hang=1.3):
    """Both arms hanging `hang` rad from the T-pose, as the library's clips start (the pose Generate blends from)."""
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        bone = rig.pose.bones[next(b.name for b in rig.data.bones if skeleton.strip_prefix(b.name) == side + "Arm")]
        rest = np.array(bone.bone.matrix_local.to_3x3(), dtype=np.float64)
        bone.rotation_mode = "QUATERNION"
        bone.rotation_quaternion = matrix_to_quat(rest.T @ rotvec_to_matrix(np.array([0.0, sign * hang, 0.0])) @ rest)


def baked(rig, start, count):
    """(F, 42)-like pieces of the baked gesture: description-joint positions (F, 10, 3) and each index
    finger's unit direction {arm: (F, 3)}, from Blender's evaluated pose (world = character frame here)."""
    names = {skeleton.strip_prefix(b.name): b.name for b in rig.pose.bones}
    world = np.array(rig.matrix_world)
    joints, fingers = [], {"LEFT": [], "RIGHT": []}
    for frame in range(start, start + count):
        bpy.context.scene.frame_set(frame)

        def head(name):
            return (world @ np.append(rig.pose.bones[names[name]].head, 1.0))[:3]
        joints.append([head(bone) for _, bone in skeleton.DESCRIPTION_JOINTS])
        for arm, prefix in skeleton.ARM_PREFIX.items():
            line = head(prefix + "HandIndex4") - head(prefix + "HandIndex1")
            fingers[arm].append(line / np.linalg.norm(line))
    return np.array(joints), {arm: np.array(v) for arm, v in fingers.items()}


def generate(rig, settings, start, **values):
    for key, value in values.items():
        setattr(settings, key, value)
    settings.start_frame = start
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    return baked(rig, start, settings.frame_count)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--targets", type=int, default=20, help="random pointing targets per arm")
    parser.add_argument("--agent", type=Path, help="agent file (default: the bundled agent)")
    options = parser.parse_args(argv)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rlanimate_addon", default_set=True)
    if options.agent:
        bpy.context.preferences.addons["rlanimate_addon"].preferences.agent_path = str(options.agent)
    rig = rig_session.load_rig(SAMPLE_RIG_BLEND, with_mesh=True)
    stand(rig)
    settings = bpy.context.scene.rlanimate
    start = 1
    wave_rows, sweeps, seed_gaps = [], {}, []
    for arm in skeleton.ARMS:
        for seed in SEEDS:
            for exaggeration in EXAGGERATIONS:
                positions, _ = generate(rig, settings, start, behaviour="WAVE", arm=arm, exaggeration=exaggeration,
                                        seed=seed)
                start += SPACING
                m = bm.wave_measures(positions, arm)
                sweeps.setdefault((arm, seed), []).append((positions, m))
                wave_rows.append([arm.lower(), seed, f"{exaggeration:.1f}", f"{m['hand_up_s']:.2f}", m["strokes"],
                                  m["cycles"], f"{m['frequency']:.2f}", f"{100 * m['swing']:.1f}",
                                  f"{metrics.smoothness(positions):.2f}"])
        for k in range(len(EXAGGERATIONS)):
            seed_gaps.append(bm.variation([sweeps[(arm, s)][k][0] for s in SEEDS]))
    rising = {f"{arm.lower()}, seed {seed}": bool(np.all(np.diff([m["swing"] for _, m in runs]) > 0))
              for (arm, seed), runs in sweeps.items()}

    rng = np.random.default_rng(TARGET_SEED)
    point_rows = []
    for arm in skeleton.ARMS:
        targets = random_targets(rng, arm, options.targets)
        angles, smoothness = {False: [], True: []}, {False: [], True: []}
        for k, location in enumerate(targets):
            target = bpy.data.objects.new(f"Target_{arm}_{k}", None)
            target.location = location
            bpy.context.scene.collection.objects.link(target)
            for exact in (False, True):
                positions, fingers = generate(rig, settings, start, behaviour="POINT", arm=arm, target=target,
                                              exact_aim=exact, seed=0)
                start += SPACING
                angles[exact].append(bm.point_measures(positions, fingers[arm], arm, location)["angle"])
                smoothness[exact].append(metrics.smoothness(positions))
        point_rows.append([arm.lower(), len(targets), f"{np.median(angles[False]):.1f}", f"{np.max(angles[False]):.1f}",
                           f"{np.median(angles[True]):.2f}", f"{np.max(angles[True]):.2f}",
                           f"{min(smoothness[False]):.2f} / {min(smoothness[True]):.2f}"])

    agent = shown(options.agent) if options.agent else "the bundled agent (rlanimate_addon/agents/default.npz)"
    lines = [
        "# Generate Gesture's behaviour, measured from Blender",
        "",
        f"Generate Gesture (the operator) on the sample character with {agent}, each gesture at the panel's "
        f"default length ({settings.frame_count} frames) from a standing pose with the arms hanging; the baked "
        "pose read back from Blender frame by frame and measured with `core/behaviour_metrics.py` "
        "(docs/METRICS.md). Regenerate: `nice -n 10 python benchmarks/generate_behaviour.py"
        f"{' --agent ' + str(agent) if options.agent else ''} --targets {options.targets}`.",
        "",
        "## Waves",
        "",
        *markdown_table(
            [
                "arm",
                "seed",
                "exaggeration",
                "hand up (s)",
                "strokes",
                "full cycles",
                "frequency (Hz)",
                "swing (cm)",
                "smoothness",
            ],
            wave_rows,
        ),
        "",
        "Swing strictly rising with the exaggeration: "
        + ", ".join(f"{k}: {'yes' if v else 'no'}" for k, v in rising.items())
        + ".",
        "",
        f"Seeds {SEEDS[0]} and {SEEDS[1]} on the same request: mean joint distance median "
        f"{100 * np.median(seed_gaps):.1f} cm (range {100 * np.min(seed_gaps):.1f}-{100 * np.max(seed_gaps):.1f}). "
        "The library's own waves make 6-10 strokes, 3-5 cycles at 2.1-2.8 Hz, swinging 9-33 cm.",
        "",
        "## Points at random targets",
        "",
        "Targets drawn over the library's ranges (azimuth -60 to 95 degrees, elevation -40 to 55, 1.5-4 m).",
        "",
        *markdown_table(
            [
                "arm",
                "targets",
                "own aim: median (deg)",
                "own aim: max",
                "Exact Aim: median",
                "Exact Aim: max",
                "smoothness, lowest: own aim / Exact Aim",
            ],
            point_rows,
        ),
        "",
        "Smoothness: `core.metrics.smoothness` of the baked description joints (below 98.5 artefacts show).",
        "",
    ]
    out = RESULTS_DIR / "generate_behaviour.md"
    out.write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
