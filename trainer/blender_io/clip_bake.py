"""Bake synthesised clips onto the sample rig and export them as FBX the way a Mixamo download comes
(Mixamo bone names, 30 fps, no leaf bones), with the library's manifest.json."""
import json
from pathlib import Path

import numpy as np

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.rotations import continuous, rotvec_to_quat
from trainer.blender_io import rig_session
from trainer.files import atomic_write_text
from trainer.motion.library_plan import DEFAULT_SEED, manifest_entry, plan_library
from trainer.motion.synthesis import FPS, synthesise
from trainer.paths import CLIP_DIR, SAMPLE_RIG_BLEND

SIMPLIFY = 0.1  # FBX curve simplification: keeps joints within 0.3 mm, drops static keys (~125 KB a clip)

def bake_clip(rig, clip, name):
    """A new action on `rig` with quaternion keys for every bone the clip animates, frames 0..F-1
    (FBX time 0 onwards, as Mixamo files start; Blender's importer shows them as frames 1..F)."""
    from rlanimate_addon.blender import action_adapter

    target = action_adapter.new_action(name, rig)
    frames = np.arange(clip.frames)
    for bone, rotvecs in clip.rotvecs.items():
        path = f'pose.bones["{skeleton.PREFIX}{bone}"].rotation_quaternion'
        quats = continuous(rotvec_to_quat(rotvecs))
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


def build_library(out_dir=CLIP_DIR, seed=DEFAULT_SEED, rig_path=SAMPLE_RIG_BLEND, only=None, log=print):
    """Synthesise, bake and export the planned clips (those named in `only`, else all) into
    `out_dir`; write their manifest.json. Returns the manifest."""
    bpy = rig_session.import_bpy()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rig_session.new_empty_scene()
    rig = rig_session.load_rig(rig_path)
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
    atomic_write_text(out_dir / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    return manifest
