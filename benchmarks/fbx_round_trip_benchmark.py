"""FBX round trip: how far re-imported joints land from the baked gesture, over many random gestures.

Generates --gestures gestures one after another on the sample rig with the bundled agent (Point and
Wave, both arms, random unseen targets 1.5-4 m away, exaggerations, seeds and lengths from 0.4x to
1.5x the learned average), exports them with Export FBX, re-imports the file with Blender's importer
(its defaults: Animation Offset 1, Automatic Bone Orientation off) and compares every bone's head on
every frame. Writes the section "FBX round trip (Blender X.Y)" of
docs/BENCHMARKS.md. The contract (issue 4): every joint within 1 mm.

Run: `python benchmarks/fbx_round_trip_benchmark.py` and `.venv-bpy42/bin/python benchmarks/fbx_round_trip_benchmark.py`
"""
import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402, I001  (before addon_utils, Blender's module, importable once bpy is)
import addon_utils  # noqa: E402
import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)

from rlanimate_addon.blender import properties  # noqa: E402
from rlanimate_addon.core import skeleton  # noqa: E402
from trainer.blender_io import rig_session  # noqa: E402
from trainer.paths import SAMPLE_RIG_BLEND, SAMPLE_RIG_FBX  # noqa: E402

COMMAND = "python benchmarks/fbx_round_trip_benchmark.py"


def load_sample_rig():
    """The sample character with its mesh in a fresh scene with the add-on on; from the .blend, or the
    FBX before 5.0 (Blender 4.2 cannot read a .blend saved by 5.0)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rlanimate_addon", default_set=True)
    source = SAMPLE_RIG_BLEND if bpy.app.version >= (5, 0, 0) else SAMPLE_RIG_FBX
    rig = rig_session.load_rig(source, with_mesh=True)
    bpy.context.view_layer.objects.active = rig
    return rig


def random_target(rng, arm):
    """An empty 1.5-4 m from the arm's rest shoulder, azimuth -30..70 degrees towards the arm's side,
    elevation -25..45 (the aim benchmark's unseen range)."""
    side = 1.0 if arm == "LEFT" else -1.0
    azimuth, elevation = np.radians(rng.uniform(-30, 70)), np.radians(rng.uniform(-25, 45))
    direction = (side * np.sin(azimuth) * np.cos(elevation), -np.cos(azimuth) * np.cos(elevation), np.sin(elevation))
    target = bpy.data.objects.new("Target", None)
    target.location = skeleton.shoulder_rest_position(arm) + rng.uniform(1.5, 4.0) * np.asarray(direction)
    bpy.context.scene.collection.objects.link(target)
    return target


def generate_gestures(rig, count, seed):
    """Bake `count` random gestures back to back from frame 1; returns the last baked frame."""
    rng = np.random.default_rng(seed)
    settings = bpy.context.scene.rlanimate
    start = 1
    for k in range(count):
        behaviour, arm = ("POINT", "WAVE")[k % 2], ("LEFT", "RIGHT")[(k // 2) % 2]
        settings.behaviour, settings.arm = behaviour, arm
        settings.frame_count = int(round(properties.learned_length(behaviour) * rng.uniform(0.4, 1.5)))
        settings.start_frame, settings.seed = start, int(rng.integers(0, 1000))
        settings.exaggeration = float(rng.uniform(0.0, 1.0))
        settings.target = random_target(rng, arm) if behaviour == "POINT" else None
        bpy.context.view_layer.objects.active = rig
        assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
        start += settings.frame_count
    return start - 1


def bone_heads(rig, frames):
    """(F, B, 3) world positions of every bone's head, in skeleton.BONES order."""
    scene, heads = bpy.context.scene, []
    bones = [rig.pose.bones[skeleton.PREFIX + b.name] for b in skeleton.BONES]
    for frame in frames:
        scene.frame_set(int(frame))
        heads.append([tuple(rig.matrix_world @ bone.head) for bone in bones])
    return np.asarray(heads)


def measure(count, seed):
    rig = load_sample_rig()
    last = generate_gestures(rig, count, seed)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "gestures.fbx"
        assert bpy.ops.rlanimate.export_fbx(filepath=str(path)) == {"FINISHED"}
        before = set(bpy.data.objects)
        bpy.ops.import_scene.fbx(filepath=str(path))  # the importer's defaults, as an animator imports it
    copy = next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")
    frames = np.arange(1, last + 1)
    error = np.linalg.norm(bone_heads(copy, frames) - bone_heads(rig, frames), axis=2)  # (F, B) metres
    return frames, error


def section(frames, error, count, seed):
    worst_per_frame = error.max(axis=1)
    worst_bone = skeleton.BONES[int(np.unravel_index(error.argmax(), error.shape)[1])].name
    version = ".".join(map(str, bpy.app.version[:2]))
    return "\n".join([
        f"## FBX round trip (Blender {version})", "",
        f"{count} gestures baked back to back on the sample rig by the bundled agent (Point and Wave, both",
        "arms, random unseen targets, exaggerations, seeds and lengths of 0.4x-1.5x the average), exported",
        "with Export FBX, re-imported with Blender's importer at its defaults (Animation Offset 1); distance of",
        "every bone's head from the baked one, on every frame. Contract: every joint within 1 mm.", "",
        f"Regenerate: `{COMMAND} --gestures {count} --seed {seed}` (Blender 4.2: `.venv-bpy42/bin/python ...`)", "",
        f"Blender {bpy.app.version_string}.", "",
        "| frames | bones | worst (mm) | 99.9th percentile of frames (mm) | median (mm) | frames over 1 mm |",
        "|---:|---:|---:|---:|---:|---:|",
        f"| {len(frames)} | {error.shape[1]} | {1e3 * error.max():.3f} ({worst_bone}) | "
        f"{1e3 * np.percentile(worst_per_frame, 99.9):.3f} | {1e3 * np.median(worst_per_frame):.4f} | "
        f"{int(np.sum(worst_per_frame > 1e-3))} |",
    ]) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gestures", type=int, default=24)
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    frames, error = measure(args.gestures, args.seed)
    text = section(frames, error, args.gestures, args.seed)
    print(text)
    if not args.no_write:
        report.write_section(text.splitlines()[0], text)


if __name__ == "__main__":
    main()
