"""The sample motion-clip library: 100 synthesised clips baked onto the sample rig and exported as
FBX the way a Mixamo download comes (Mixamo bone names, 30 fps, no leaf bones), plus manifest.json.

    python -m trainer.clip_library [--seed S] [--out DIR]
    python trainer/clip_library.py [--seed S] [--out DIR]

regenerate the whole library deterministically from one seed. The plan (which clips, which labels,
which split) is plain data; only baking and export touch bpy.

Plan, as in the paper: 50 point clips (25 per arm; targets 1.5-4 m away over the reachable front
hemisphere: across the body, ahead, out to the side, low to high) and 50 wave clips (25 per arm,
exaggeration spread over [0, 1]). 10 are held out for testing: 3 point clips per arm (targets inside
the training spread, never reused) and 2 wave clips per arm at exaggerations no training clip has.
"""
import json
import os
import sys
from dataclasses import dataclass
from pathlib import Path

if __package__ in (None, ""):  # run as a script: put the repository on the path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from rlanimate_addon.core import skeleton, spaces
from rlanimate_addon.core.rotations import rotvec_to_quat
from trainer import bpy_support
from trainer.gesture_synthesis import FPS, GestureSpec, synthesise

DEFAULT_SEED = 2021
CLIP_DIR = bpy_support.REPO_ROOT / "sample_rigs" / "clips"
CLIPS_PER_ARM = 25
# Pointing targets: a 5 x 5 grid of (azimuth, elevation) cells from the pointing shoulder, one
# target jittered inside each cell. Azimuth 0 is straight ahead, positive out to the arm's side,
# negative across the body; elevation is from the horizontal.
AZIMUTH_RANGE = np.radians([-60.0, 95.0])
ELEVATION_RANGE = np.radians([-40.0, 55.0])
DISTANCE_RANGE = (1.5, 4.0)
LOWEST_TARGET = 0.05  # m above the floor
TEST_POINT_CELLS = ((1, 3), (2, 1), (3, 2))  # (azimuth band, elevation band): interior cells
TEST_WAVE_INDICES = (6, 18)
SIMPLIFY = 0.1  # FBX curve simplification: keeps joints within 0.3 mm, drops static keys (~125 KB a clip)


@dataclass(frozen=True)
class PlannedClip:
    file: str
    spec: GestureSpec
    split: str  # "train" or "test"


def _point_targets(arm, rng):
    """25 targets (cell, xyz) for one arm, one per (azimuth, elevation) cell, in cell order."""
    sign = 1.0 if arm == "LEFT" else -1.0
    shoulder = skeleton.shoulder_rest_position(arm)
    az_edges = np.linspace(*AZIMUTH_RANGE, 6)
    el_edges = np.linspace(*ELEVATION_RANGE, 6)
    distances = rng.permutation(np.linspace(*DISTANCE_RANGE, CLIPS_PER_ARM)) + rng.uniform(-0.04, 0.04, CLIPS_PER_ARM)
    targets = []
    for i in range(5):
        for j in range(5):
            az = rng.uniform(az_edges[i] + 0.15 * (az_edges[1] - az_edges[0]), az_edges[i + 1] - 0.15 * (az_edges[1] - az_edges[0]))
            el = rng.uniform(el_edges[j] + 0.15 * (el_edges[1] - el_edges[0]), el_edges[j + 1] - 0.15 * (el_edges[1] - el_edges[0]))
            direction = np.array([sign * np.sin(az) * np.cos(el), -np.cos(az) * np.cos(el), np.sin(el)])
            distance = float(np.clip(distances[5 * i + j], *DISTANCE_RANGE))
            if direction[2] < 0:  # keep low targets above the floor
                distance = min(distance, (shoulder[2] - LOWEST_TARGET) / -direction[2])
            targets.append(((i, j), np.round(shoulder + distance * direction, 4)))
    return targets


def _wave_exaggerations(arm):
    """25 exaggerations for one arm; the two arms use interleaved grids, so no value repeats."""
    if arm == "LEFT":
        return np.round(np.linspace(0.0, 1.0, CLIPS_PER_ARM), 4)
    return np.round(np.linspace(0.02, 0.98, CLIPS_PER_ARM), 4)


def plan_library(seed=DEFAULT_SEED):
    """The 100 PlannedClips of the library, deterministic in `seed`."""
    rng = np.random.default_rng(seed)
    style_seeds = iter(rng.integers(0, 2**31 - 1, size=4 * CLIPS_PER_ARM))
    plan = []
    for arm in skeleton.ARMS:
        for k, (cell, target) in enumerate(_point_targets(arm, rng)):
            split = "test" if cell in TEST_POINT_CELLS else "train"
            spec = GestureSpec("POINT", arm, target=tuple(float(v) for v in target), seed=int(next(style_seeds)))
            plan.append(PlannedClip(f"point_{arm.lower()}_{k:03d}.fbx", spec, split))
    for arm in skeleton.ARMS:
        for k, exaggeration in enumerate(_wave_exaggerations(arm)):
            split = "test" if k in TEST_WAVE_INDICES else "train"
            spec = GestureSpec("WAVE", arm, exaggeration=float(exaggeration), seed=int(next(style_seeds)))
            plan.append(PlannedClip(f"wave_{arm.lower()}_{k:03d}.fbx", spec, split))
    return plan


def manifest_entry(planned, frames):
    spec = planned.spec
    point = spec.behaviour == "POINT"
    return {
        "file": planned.file, "behaviour": spec.behaviour, "arm": spec.arm,
        "target": list(spec.target) if point else None,
        "direction": [round(float(v), 6) for v in spaces.pointing_direction(spec.arm, spec.target)] if point else None,
        "exaggeration": None if point else spec.exaggeration,
        "frames": int(frames), "fps": FPS, "split": planned.split,
    }


# --- Blender side -------------------------------------------------------------------------------

def _continuous_quaternions(rotvecs):
    """(F, 3) rotation vectors -> (F, 4) quaternions with no sign flips between frames."""
    quats = rotvec_to_quat(rotvecs)
    signs = np.sign(np.einsum("fi,fi->f", quats[1:], quats[:-1]))
    signs[signs == 0] = 1.0
    return quats * np.concatenate([[1.0], np.cumprod(signs)])[:, None]


def bake_clip(rig, clip, name):
    """A new action on `rig` with quaternion keys for every bone the clip animates, frames 0..F-1
    (FBX time 0 onwards, as Mixamo files start; Blender's importer shows them as frames 1..F)."""
    from rlanimate_addon.blender import action_adapter

    target = action_adapter.new_action(name, rig)
    frames = np.arange(clip.frames)
    for bone, rotvecs in clip.rotvecs.items():
        path = f'pose.bones["{skeleton.PREFIX}{bone}"].rotation_quaternion'
        quats = _continuous_quaternions(rotvecs)
        for index in range(4):
            action_adapter.write_keys(target.new_fcurve(path, index, skeleton.PREFIX + bone), frames, quats[:, index])
    action_adapter.assign(rig, target)
    return target.action


def export_fbx(bpy, rig, path, frames):
    """Export the rig's active action as a Mixamo-style FBX (armature only, baked, 30 fps)."""
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    scene.frame_start, scene.frame_end = 0, frames - 1
    bpy.context.view_layer.update()
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj == rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.export_scene.fbx(
        filepath=str(path), use_selection=True, object_types={"ARMATURE"}, add_leaf_bones=False,
        bake_anim=True, bake_anim_use_all_bones=False,
        bake_anim_use_nla_strips=False, bake_anim_use_all_actions=False, bake_anim_force_startend_keying=True,
        bake_anim_step=1.0, bake_anim_simplify_factor=SIMPLIFY, axis_forward="-Z", axis_up="Y",
        apply_unit_scale=True, apply_scale_options="FBX_SCALE_NONE", primary_bone_axis="Y", secondary_bone_axis="X")


def build_library(out_dir=CLIP_DIR, seed=DEFAULT_SEED, rig_path=bpy_support.SAMPLE_RIG_BLEND, only=None, log=print):
    """Synthesise, bake and export the planned clips (those named in `only`, else all) into
    `out_dir`; write their manifest.json. Returns the manifest."""
    bpy = bpy_support.import_bpy()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    bpy_support.new_empty_scene()
    rig = bpy_support.load_rig(rig_path)
    entries = []
    for planned in plan_library(seed):
        if only and planned.file not in only:
            continue
        clip = synthesise(planned.spec)
        action = bake_clip(rig, clip, Path(planned.file).stem)
        export_fbx(bpy, rig, out_dir / planned.file, clip.frames)
        rig.animation_data.action = None
        bpy.data.actions.remove(action)
        entries.append(manifest_entry(planned, clip.frames))
        log(f"{planned.file}: {clip.frames} frames ({planned.split})")
    manifest = {"fps": FPS, "rig": "../character.fbx", "seed": seed, "clips": entries}
    tmp = out_dir / "manifest.json.tmp"
    tmp.write_text(json.dumps(manifest, indent=1) + "\n")
    os.replace(tmp, out_dir / "manifest.json")
    return manifest


def main():
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED)
    parser.add_argument("--out", type=Path, default=CLIP_DIR)
    parser.add_argument("--only", nargs="*", help="regenerate just these files (e.g. point_left_000.fbx)")
    args = parser.parse_args(bpy_support.script_args())
    manifest = build_library(args.out, args.seed, only=args.only)
    print(f"wrote {len(manifest['clips'])} clips and manifest.json to {args.out}")


if __name__ == "__main__":
    main()
