"""Reading a rig, its pose and a target out of Blender, and writing a gesture's keys back in.

Bones are matched by their Mixamo name with any `prefix:` stripped, so 'mixamorig:LeftArm',
'mixamorig1:LeftArm' and 'LeftArm' all serve as LeftArm. Positions are in the rig's armature space,
in the rig's own units; the bpy-free gesture code only uses directions and rotations from them.
"""
import bpy
import numpy as np

from ..core import skeleton
from ..core.errors import RLAnimateError
from ..core.gesture import RigPose
from . import action_adapter


def rig_bone_names(obj):
    """Mapping canonical bone name -> the rig's bone name (the first one, if several prefixes match)."""
    names = {}
    for bone in obj.data.bones:
        names.setdefault(skeleton.strip_prefix(bone.name), bone.name)
    return names


def check_rig(obj):
    """The rig's bone-name map; RLAnimateError when obj is not an armature with every required bone."""
    if obj is None or obj.type != "ARMATURE":
        raise RLAnimateError("The active object is not an armature: select the character's armature.")
    names = rig_bone_names(obj)
    missing = sorted(set(skeleton.REQUIRED_BONES) - set(names))
    if missing:
        raise RLAnimateError(f"Armature {obj.name!r} lacks the bones {', '.join(missing)}: "
                             "use a rig with Mixamo bone names.")
    return names


def check_quaternion_bones(obj, bone_names):
    """RLAnimateError naming the bones that would ignore quaternion keys (Euler or axis-angle mode)."""
    others = [name for name in bone_names if obj.pose.bones[name].rotation_mode != "QUATERNION"]
    if others:
        raise RLAnimateError(f"Bones {', '.join(others)} do not use quaternion rotation: set their "
                             "Rotation Mode to Quaternion (WXYZ) in the Bone properties.")


def read_rig_pose(obj, names):
    """RigPose of the rig as it is posed now (evaluate the start frame first when it is animated)."""
    heads, frames, starts = {}, {}, {}
    for canonical, name in names.items():
        bone = obj.data.bones[name]
        heads[canonical] = np.array(bone.head_local, dtype=np.float64)
        rotation = np.array(bone.matrix_local, dtype=np.float64)[:3, :3]
        frames[canonical] = rotation / np.linalg.norm(rotation, axis=0, keepdims=True)
        starts[canonical] = np.array(obj.pose.bones[name].matrix_basis.to_quaternion(), dtype=np.float64)
    return RigPose(heads, frames, starts)


def may_move(obj):
    """True when the object's world transform can change over time (keys, drivers, constraints, parent)."""
    if len(obj.constraints):
        return True
    if obj.parent is not None:
        if may_move(obj.parent) or (obj.parent_type == "BONE" and action_adapter.is_animated(obj.parent)):
            return True
    data = obj.animation_data
    if data is None:
        return False
    if any(not d.data_path.startswith("pose.") for d in data.drivers):
        return True
    targets = action_adapter.strip_targets(obj)
    active = action_adapter.active_target(obj)
    targets += [active] if active is not None else []
    return any(not fcurve.data_path.startswith("pose.") for t in targets for fcurve in t.fcurves())


def _world_point(target, scene):
    """World position (3,) of the target object, or of the 3D cursor when target is None."""
    location = scene.cursor.location if target is None else target.matrix_world.translation
    return np.array(location, dtype=np.float64)


def _to_armature(obj, point):
    return (np.array(obj.matrix_world.inverted(), dtype=np.float64) @ np.append(point, 1.0))[:3]


def target_positions(scene, obj, target, frames):
    """(N, 3) target positions in the armature's space at each frame (the 3D cursor when target is None).

    A target or armature that can move is read at every frame with scene.frame_set; a still one once.
    The caller restores the scene's frame.
    """
    if (target is not None and may_move(target)) or may_move(obj):
        points = []
        for frame in frames:
            scene.frame_set(int(frame))
            points.append(_to_armature(obj, _world_point(target, scene)))
        return np.array(points)
    return np.tile(_to_armature(obj, _world_point(target, scene)), (len(frames), 1))


def write_gesture(obj, name, bone_names, start_frame, quats):
    """Key the (N, B, 4) local quaternions of bone_names from start_frame into a new action called `name`.

    On a rig with no animation the action becomes the active action. Otherwise the active action
    (if any) is pushed down to the NLA, as Blender's Push Down does, and the gesture goes on a new
    NLA track above it, with no effect outside its frames. Returns the new action.
    """
    target = action_adapter.new_action(name, obj)
    frames = start_frame + np.arange(len(quats))
    for b, bone in enumerate(bone_names):
        path = f'pose.bones["{bpy.utils.escape_identifier(bone)}"].rotation_quaternion'
        for channel in range(4):
            action_adapter.write_keys(target.new_fcurve(path, channel, bone), frames, quats[:, b, channel])
    if action_adapter.is_animated(obj):
        action_adapter.push_down(obj)
        action_adapter.add_strip(obj, target, start_frame, target.action.name)
    else:
        action_adapter.assign(obj, target)
    return target.action
