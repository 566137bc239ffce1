"""Helpers for the extension tests: enabling the add-on, rigs, targets, running Generate, reading poses.

Rigs come from the committed sample character, or are built from the canonical skeleton with other
units, another armature-space orientation and other bone rolls, as a Mixamo FBX import has them.
"""
from pathlib import Path  # noqa: I001  (bpy before addon_utils, Blender's own module, importable once bpy is)

import bpy
import addon_utils
import numpy as np

from rlanimate_addon.core import skeleton

ROOT = Path(__file__).resolve().parents[2]
SAMPLE_BLEND = ROOT / "sample_rigs" / "character.blend"
SAMPLE_FBX = ROOT / "sample_rigs" / "character.fbx"
SAMPLE_RIG = "RLAnimate_Character"
ADDON = "rlanimate_addon"


def enable_addon():
    """Reset to a factory-fresh empty scene and enable the add-on; returns Scene.rlanimate."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable(ADDON, default_set=True, handle_error=_raise)
    return bpy.context.scene.rlanimate


def disable_addon():
    addon_utils.disable(ADDON, default_set=True, handle_error=_raise)


def _raise(error):
    raise error


def addon_preferences():
    return bpy.context.preferences.addons[ADDON].preferences


def activate(obj):
    bpy.context.view_layer.objects.active = obj
    return obj


def load_sample_rig():
    """The sample character (armature and skinned mesh) brought into the scene; returns the armature.

    From the .blend; Blender 4.2 cannot read a .blend saved by 5.0, so there from the sample FBX.
    """
    if bpy.app.version < (5, 0, 0):
        before = set(bpy.data.objects)
        bpy.ops.import_scene.fbx(filepath=str(SAMPLE_FBX), automatic_bone_orientation=False)
        return activate(next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE"))
    with bpy.data.libraries.load(str(SAMPLE_BLEND), link=False) as (source, target):
        target.objects = list(source.objects)
    for obj in target.objects:
        bpy.context.scene.collection.objects.link(obj)
    return activate(bpy.data.objects[SAMPLE_RIG])


IDENTITY_AXES = np.eye(3)


def build_rig(name, *, units=1.0, axes=IDENTITY_AXES, roll_to_x=False, prefix=skeleton.PREFIX, skip=()):
    """A Mixamo-named armature from the canonical skeleton, standing where the canonical one stands.

    Its armature space is `units` times the canonical and rotated by `axes` (3, 3), and its object
    transform undoes both. roll_to_x turns every bone's roll by 90 degrees; `skip` leaves bones out.
    """
    data = bpy.data.armatures.new(name)
    rig = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(rig)
    activate(rig)
    bpy.ops.object.mode_set(mode="EDIT")
    for bone in skeleton.BONES:
        if bone.name in skip:
            continue
        edit = data.edit_bones.new(prefix + bone.name)
        edit.head = units * axes @ np.asarray(bone.head)
        edit.tail = units * axes @ np.asarray(bone.tail)
        hint = skeleton.rest_frame(bone)[:, 0] if roll_to_x else np.asarray(bone.z_hint)
        edit.align_roll(axes @ hint)
        if bone.parent is not None and bone.parent not in skip:
            edit.parent = data.edit_bones[prefix + bone.parent]
    bpy.ops.object.mode_set(mode="OBJECT")
    world = np.eye(4)
    world[:3, :3] = axes.T / units
    rig.matrix_world = world.T.tolist()  # mathutils takes rows
    for pose_bone in rig.pose.bones:
        pose_bone.rotation_mode = "QUATERNION"
    return rig


def add_empty(name, location):
    empty = bpy.data.objects.new(name, None)
    empty.location = location
    bpy.context.scene.collection.objects.link(empty)
    return empty


def generate(rig, settings, **values):
    """Set Scene.rlanimate from `values` and run Generate Gesture on `rig` alone (active, the only one
    selected); returns the operator result."""
    for key, value in values.items():
        setattr(settings, key, value)
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj is rig)
    activate(rig)
    return bpy.ops.rlanimate.generate_gesture()


def bone_heads(rig, bones, frames):
    """(F, len(bones), 3) world positions of the bones' heads at each frame (evaluated by frame_set)."""
    scene = bpy.context.scene
    world = np.array(rig.matrix_world)
    out = []
    for frame in frames:
        scene.frame_set(int(frame))
        heads = [world @ np.append(rig.pose.bones[b].head, 1.0) for b in bones]
        out.append(np.array(heads)[:, :3])
    return np.array(out)


def rig_bone(rig, canonical):
    """The rig's bone name for a canonical bone name."""
    return next(b.name for b in rig.data.bones if skeleton.strip_prefix(b.name) == canonical)


def stand_neutral(rig, hang=1.3):
    """Pose both arms hanging `hang` radians down from the T-pose, as the clips start: the start pose."""
    from rlanimate_addon.core.rotations import matrix_to_quat, rotvec_to_matrix

    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        bone = rig.data.bones[rig_bone(rig, side + "Arm")]
        to_character = np.array(rig.matrix_world.to_3x3().normalized(), dtype=np.float64)
        rest = to_character @ np.array(bone.matrix_local.to_3x3(), dtype=np.float64)  # world rest frame
        down = rotvec_to_matrix(np.array([0.0, sign * hang, 0.0]))  # about the world's Y axis
        local = rest.T @ down @ rest
        rig.pose.bones[bone.name].rotation_quaternion = matrix_to_quat(local)
