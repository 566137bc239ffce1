"""Export FBX re-imported with Blender's FBX importer at its defaults (Animation Offset 1): how far the right
hand lands from where it was baked, with the take timed from 0 (Export FBX) and as Blender's exporter times
it alone (frame F at time F / fps).

Two characters with animation of their own: the sample character with an idle (its spine swaying over frames
1-90) under a 60-frame Wave Right baked from frame 1, and the Quaternius character
(`../shared/rigs/other/quaternius_female_casual.fbx`, skipped when absent) playing its own Female_Idle
(Generate does not map its bone names). Writes the section "Export FBX frame offset" of docs/BENCHMARKS.md.

Run: `python benchmarks/export_offset_benchmark.py [--no-write]`
"""
import argparse
import contextlib
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "addon"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)

import addon_helpers as helpers  # noqa: E402  (tests/addon/addon_helpers.py)
from rlanimate_addon.blender import export  # noqa: E402

HEADING = "## Export FBX frame offset"
COMMAND = "python benchmarks/export_offset_benchmark.py"
QUATERNIUS = ROOT.parent / "shared" / "rigs" / "other" / "quaternius_female_casual.fbx"


def sample_with_idle():
    """(rig, right hand bone, frames): the sample character, a spine idle of its own, a wave baked over it."""
    settings = helpers.enable_addon()
    rig = helpers.load_sample_rig()
    spine = rig.pose.bones[helpers.rig_bone(rig, "Spine")]
    for frame, angle in ((1, -0.1), (30, 0.1), (60, -0.1), (90, 0.1)):
        spine.rotation_quaternion = (np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2))
        spine.keyframe_insert("rotation_quaternion", frame=frame)
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT", start_frame=1, frame_count=60) == \
        {"FINISHED"}
    return rig, helpers.rig_bone(rig, "RightHand"), np.arange(1, 91)


def quaternius_idle():
    """(rig, right hand bone, frames): the Quaternius character playing its own idle (frames 1-101)."""
    helpers.enable_addon()
    bpy.ops.import_scene.fbx(filepath=str(QUATERNIUS))
    rig = helpers.activate(next(o for o in bpy.data.objects if o.type == "ARMATURE"))
    rig.animation_data.action = bpy.data.actions["HumanArmature|HumanArmature|Female_Idle"]
    return rig, "Palm.R", np.arange(1, 102)


def hand_path(rig, bone, frames):
    """(F, 3) world positions of the bone's head at `frames`."""
    pose_bone, path = rig.pose.bones[bone], []
    for frame in frames:
        bpy.context.scene.frame_set(int(frame))
        path.append(np.array(rig.matrix_world @ pose_bone.head))
    return np.array(path)


def measure(setup, timed_from_zero):
    """(offsets (F,) in cm, re-imported action's frame range) of one export and re-import."""
    rig, bone, frames = setup()
    bpy.context.scene.frame_start, bpy.context.scene.frame_end = int(frames[0]), int(frames[-1])
    baked = hand_path(rig, bone, frames)
    timing = export.take_from_time_zero
    if not timed_from_zero:  # Blender's exporter alone, as Export FBX was
        export.take_from_time_zero = contextlib.nullcontext
    try:
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "character.fbx"
            assert bpy.ops.rlanimate.export_fbx(filepath=str(path)) == {"FINISHED"}
            before = set(bpy.data.objects)
            bpy.ops.import_scene.fbx(filepath=str(path))  # the importer's defaults
    finally:
        export.take_from_time_zero = timing
    copy = next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")
    offsets = 100 * np.linalg.norm(hand_path(copy, bone, frames) - baked, axis=1)
    return offsets, tuple(int(f) for f in copy.animation_data.action.frame_range)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    cases = [("sample character, idle + wave", sample_with_idle)]
    if QUATERNIUS.is_file():
        cases.append(("Quaternius character, its own idle", quaternius_idle))
    rows = []
    for label, setup in cases:
        for timing, from_zero in (("F / fps (Blender's exporter alone, before)", False),
                                  ("from 0 (Export FBX)", True)):
            offsets, frame_range = measure(setup, from_zero)
            rows.append(f"| {label} | {timing} | {np.median(offsets):.4f} | {offsets.max():.4f} | "
                        f"{frame_range[0]}-{frame_range[1]} |")
    text = "\n".join([
        HEADING, "",
        "Export FBX re-imported with Blender's FBX importer at its defaults (Animation Offset 1, as an animator",
        "imports a file): distance of the right hand from where it was baked, on every frame of the animation, in",
        "cm; and the frames the re-imported action spans (baked from frame 1). Before, the take was timed as",
        "Blender's exporter times a scene's take (frame F at F / fps), so every key came back one frame late.", "",
        f"Regenerate: `{COMMAND}`", "",
        f"Blender {bpy.app.version_string}.", "",
        "| character | take timed | median (cm) | worst (cm) | re-imported frames |",
        "|---|---|---:|---:|---|",
        *rows,
    ]) + "\n"
    print(text)
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
