"""Export FBX re-imported with Blender's FBX importer at its defaults (Animation Offset 1): how far the right
hand lands from where it was baked, on every keyed frame, with the take timed as Export FBX times it (frame F
at (F - 1) / fps), as Export FBX timed it before issue 44 (from time 0 on the exported range's first frame),
and as Blender's exporter times it alone (frame F at F / fps).

Characters with animation of their own: the sample character with an idle (its spine swaying over frames
1-90) under a 60-frame Wave Right baked from frame 1; the same wave baked from frame -20 (the scene from 1);
the same wave baked from frame 60 in a scene starting at frame 50; and the Quaternius character
(`../shared/rigs/other/quaternius_female_casual.fbx`, skipped when absent) playing its own Female_Idle
(Generate does not map its bone names). Writes the section "Export FBX frame offset" of docs/BENCHMARKS.md.

Run: `python benchmarks/export_offset_benchmark.py [--no-write]`
"""
import argparse
import contextlib
import functools
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


def sample_with_idle(start=1, scene_start=1, idle=True):
    """(rig, right hand bone, the frames that move): the sample character in a scene of frames
    `scene_start`-250, with an idle of its own (its spine swaying over frames 1-90) unless not `idle`, a
    60-frame wave baked over it from `start`."""
    settings = helpers.enable_addon()
    bpy.context.scene.frame_start = scene_start
    rig = helpers.load_sample_rig()
    spine = rig.pose.bones[helpers.rig_bone(rig, "Spine")]
    for frame, angle in ((1, -0.1), (30, 0.1), (60, -0.1), (90, 0.1)) if idle else ():
        spine.rotation_quaternion = (np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2))
        spine.keyframe_insert("rotation_quaternion", frame=frame)
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT", start_frame=start, frame_count=60) == \
        {"FINISHED"}
    moving = np.arange(min(1, start), max(90, start + 59) + 1) if idle else np.arange(start, start + 60)
    return rig, helpers.rig_bone(rig, "RightHand"), moving


def quaternius_idle():
    """(rig, right hand bone, frames): the Quaternius character playing its own idle (frames 1-101)."""
    helpers.enable_addon()
    bpy.ops.import_scene.fbx(filepath=str(QUATERNIUS))
    rig = helpers.activate(next(o for o in bpy.data.objects if o.type == "ARMATURE"))
    rig.animation_data.action = bpy.data.actions["HumanArmature|HumanArmature|Female_Idle"]
    bpy.context.scene.frame_start, bpy.context.scene.frame_end = 1, 101
    return rig, "Palm.R", np.arange(1, 102)


@contextlib.contextmanager
def _from_time_zero(first, last):
    """The take timed as Export FBX timed it before issue 44: its first exported frame at time 0 (the
    exporter's start_zero), over the scene's range (which cannot start below 0)."""
    from io_scene_fbx import export_fbx_bin

    timed = export_fbx_bin.fbx_animations_do
    export_fbx_bin.fbx_animations_do = lambda data, ref, f_start, f_end, zero, *a, **k: timed(
        data, ref, f_start, f_end, True, *a, **k)
    scene = bpy.context.scene
    kept = scene.frame_start, scene.frame_end
    scene.frame_start, scene.frame_end = max(0, first), last
    try:
        yield
    finally:
        export_fbx_bin.fbx_animations_do = timed
        scene.frame_start, scene.frame_end = kept


#: How the take is timed: Export FBX's context for its scene take, or the ones it is compared with.
TIMINGS = {"(F - 1) / fps (Export FBX)": None, "from 0 (the range's first frame at time 0)": _from_time_zero,
           "F / fps (Blender's exporter alone)": lambda first, last: contextlib.nullcontext()}


def hand_path(rig, bone, frames):
    """(F, 3) world positions of the bone's head at `frames`."""
    pose_bone, path = rig.pose.bones[bone], []
    for frame in frames:
        bpy.context.scene.frame_set(int(frame))
        path.append(np.array(rig.matrix_world @ pose_bone.head))
    return np.array(path)


def measure(setup, timing):
    """(offsets (F,) in cm, re-imported action's frame range) of one export and re-import."""
    rig, bone, frames = setup()
    baked = hand_path(rig, bone, frames)
    own = export.take_at_own_frames
    if TIMINGS[timing] is not None:
        export.take_at_own_frames = TIMINGS[timing]
    try:
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "character.fbx"
            assert bpy.ops.rlanimate.export_fbx(filepath=str(path)) == {"FINISHED"}
            before = set(bpy.data.objects)
            bpy.ops.import_scene.fbx(filepath=str(path))  # the importer's defaults
    finally:
        export.take_at_own_frames = own
    copy = next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")
    offsets = 100 * np.linalg.norm(hand_path(copy, bone, frames) - baked, axis=1)
    return offsets, tuple(int(f) for f in copy.animation_data.action.frame_range)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    cases = [("sample character, idle + wave from frame 1", sample_with_idle),
             ("the same, wave from frame -20", functools.partial(sample_with_idle, -20)),
             ("sample character, no idle, wave from frame 60, scene from frame 50",
              functools.partial(sample_with_idle, 60, 50, idle=False))]
    if QUATERNIUS.is_file():
        cases.append(("Quaternius character, its own idle, scene 1-101", quaternius_idle))
    rows = []
    for label, setup in cases:
        for timing in TIMINGS:
            offsets, frame_range = measure(setup, timing)
            rows.append(f"| {label} | {timing} | {np.median(offsets):.4f} | {offsets.max():.4f} | "
                        f"{frame_range[0]}-{frame_range[1]} |")
    text = "\n".join([
        HEADING, "",
        "Export FBX re-imported with Blender's FBX importer at its defaults (Animation Offset 1, as an animator",
        "imports a file): distance of the right hand from where it was baked, on every frame that moves (the idle's",
        "and the wave's), in cm; and the frames the re-imported action spans (the scene's range, 1-250 unless",
        "said, and the rig's animation). Export FBX writes frame F at time (F - 1) / fps, so the",
        "importer puts every key back on its own frame whatever the scene's start. Timed from 0, a take",
        "starting on another frame than 1 moves (and frames below 0, which a scene's range cannot hold, are",
        "lost); timed as Blender's exporter times a scene's take, every key comes back one frame late.", "",
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
