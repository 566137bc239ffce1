"""Reading a rig, its animation and a target out of Blender (blender/key_layers.py writes a gesture's keys).

Bones are matched to roles by core.rig_roles (Mixamo names with any prefix, Rigify, Unreal, Auto-Rig
Pro, VRoid/VRM, Character Creator, Blender's metarig) or by a bone-map file. Positions are in the
rig's armature space, in the rig's own units; the bpy-free gesture code only uses directions and
rotations from them.
"""
from pathlib import Path

import bpy
import numpy as np

from ..core import rig_roles, vrm
from ..core.errors import RLAnimateError
from ..core.gesture import RigState, role_skeleton
from ..core.regular_file import open_regular
from . import action_adapter, playback, pose_underneath, rigify, vrm_map


def rig_roles_of(obj, bone_map_path="", read_vrm=True):
    """(family name, {role: bone name}) of an armature: from the bone-map file when one is given, else
    from its VRM humanoid map (its VRM file, or the VRM add-on's data; blender/vrm_map.py), else
    detected from its bone names. RLAnimateError when obj is not an armature. read_vrm=False (the panel's
    draw()): a VRM file is not read, only looked up where an operator read it."""
    if obj is None or obj.type != "ARMATURE":
        raise RLAnimateError("The active object is not an armature: select the character's armature.")
    names = obj.data.bones.keys()
    if bone_map_path:
        return rig_roles.read_bone_map(_bone_map_text(Path(bpy.path.abspath(bone_map_path))), names)
    roles = vrm_map.roles_of(obj, read_vrm)
    if roles:
        return vrm.FAMILY, roles
    family, roles = rig_roles.detect(names, rigify=rigify.is_generated(obj))
    return family.name, roles


def _bone_map_text(path):
    """The text of the bone-map file at `path`: a regular file (a FIFO or /dev/stdin would block every
    redraw) of at most MAX_BONE_MAP_BYTES (/dev/zero is endless), UTF-8."""
    try:
        with open_regular(path) as handle:
            data = handle.read(rig_roles.MAX_BONE_MAP_BYTES + 1)
    except (OSError, ValueError) as error:  # ValueError: a NUL in the path
        reason = getattr(error, "strerror", None) or error
        raise RLAnimateError(f"Cannot read the bone-map file {str(path)!r} ({reason}): pick a bone-map JSON "
                             "file saved from the panel, or clear the Bone Map field to detect the bones.") from None
    if len(data) > rig_roles.MAX_BONE_MAP_BYTES:
        raise RLAnimateError(f"The bone-map file {str(path)!r} is larger than {rig_roles.MAX_BONE_MAP_BYTES >> 10} KB, "
                             "so it is not a bone map: pick a bone-map JSON file saved from the panel, or clear the "
                             "Bone Map field.")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise RLAnimateError(f"The bone-map file {str(path)!r} is not UTF-8 text: pick a bone-map JSON file saved "
                             "from the panel, or clear the Bone Map field.") from None


def check_hips(obj, roles):
    """RLAnimateError when the bone playing Hips hangs below a spine bone (GDQuest's robot: its torso carries
    its hips): the gesture keys the spine, and reads where a target is from the hips' motion underneath."""
    hips = roles.get("Hips")
    above = set() if hips is None else {bone.name for bone in obj.data.bones[hips].parent_recursive}
    spine = [roles[role] for role in rig_roles.SPINE if roles.get(role) in above]
    if spine:
        parent = obj.data.bones[spine[0]].parent
        raise RLAnimateError(
            f"The Hips bone {hips!r} of {obj.name!r} hangs below the Spine bone {spine[0]!r}, but the gesture keys "
            "the spine from the hips up: in the bone-map file, map Hips to "
            + (f"the bone the spine hangs from, {parent.name!r}." if parent else "a bone above the spine."))


def read_skeleton(obj, roles):
    """The bones playing roles as a RigSkeleton (gesture.role_skeleton; rest matrices in armature space,
    the rig's units)."""
    bones = obj.data.bones
    rest = {b: np.array(bones[b].matrix_local, dtype=np.float64) for b in roles.values()}
    return role_skeleton(roles, rest, {b: bones[b].length for b in roles.values()})


def rotation_basis(pose_bone, values):
    """(4, 4) basis matrix of the rotation given by channel values (C,) in the bone's own rotation mode."""
    basis = np.eye(4)
    basis[:3, :3] = pose_underneath.rotation_matrices(pose_bone.rotation_mode, np.asarray([values], dtype=float))[0]
    return basis


def sample_rig(context, obj, roles, family, frames, target=None, target_bone="", extra=(), properties=()):
    """(RigState, {bone: (N, C) rotation channel values underneath}, targets (N, 3), playback.Played of the `extra`
    bones (their pose) and custom `properties` ((bone, name)), or None when none are asked for).

    The bones playing roles are read (their basis and their evaluated pose, constraints included) at
    every frame of an animated rig, as its action, NLA and drivers play it: from their keys in numpy
    where the pose underneath allows it and the rig and target stand still (blender/pose_underneath.py), else
    through Blender, each frame once (blender/playback.py); a still rig once. The target (an object, a bone of
    an armature when target_bone names one, or the 3D cursor when target is None) is read in the rig's armature
    space at each frame where anything can move it. The caller restores the scene's frame.
    """
    scene = context.scene
    animated = action_adapter.plays(obj)
    target_moves = target is not None and (may_move(target) or (target_bone and action_adapter.is_animated(target)))
    skeleton = read_skeleton(obj, roles)
    count = len(frames)
    evaluated = None
    if animated and not may_move(obj) and not target_moves and not properties:
        evaluated = pose_underneath.sample(obj, list(skeleton.names) + list(extra), frames)
    if evaluated is not None:
        basis, poses, values = evaluated
        names = len(skeleton.names)
        under, poses, values = _one_frame_if_still(basis[:, :names], poses[:, :names],
                                                   {b: values[b] for b in skeleton.names})
        rig = RigState(obj.name, skeleton, roles, family, under, animated, under_pose=poses)
        targets = np.broadcast_to(target_point(obj, target, target_bone, scene), (count, 3))
        extras = playback.Played(basis[:, names:], evaluated[1][:, names:], {}, targets, {}) if extra else None
        return rig, values, targets, extras
    moving = animated or may_move(obj) or target_moves
    played = playback.play(scene, obj, list(skeleton.names) + list(extra), frames, moving,
                           lambda: target_point(obj, target, target_bone, scene), properties)
    names = len(skeleton.names)
    under, poses, values = _one_frame_if_still(played.basis[:, :names], played.pose[:, :names],
                                               {b: played.values[b] for b in skeleton.names})
    rig = RigState(obj.name, skeleton, roles, family, under, animated, under_pose=poses)
    extras = None
    if extra or properties:
        extras = playback.Played(played.basis[:, names:], played.pose[:, names:], {}, played.targets,
                                 played.properties)
    return rig, values, played.targets, extras


def _one_frame_if_still(under, poses, values):
    """(basis, pose, {bone: channel values}) underneath as their first frame broadcast over the frames when
    nothing moves over them: a pose that stands still is then read as a still rig's is, to the last bit."""
    if under.strides[0] == 0 or np.ptp(under, axis=0).any() or np.ptp(poses, axis=0).any() or any(
            np.ptp(v, axis=0).any() for v in values.values()):
        return under, poses, values

    def first(m):
        return np.broadcast_to(np.array(m[:1]), m.shape)
    return first(under), first(poses), {bone: first(v) for bone, v in values.items()}


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
    # An importer keys the object's transform too (FBX clips): keys that all hold one value do not move it.
    return any(not fcurve.data_path.startswith("pose.") and not action_adapter.holds_still(fcurve)
               for t in targets for fcurve in t.fcurves())


def target_point(obj, target, target_bone, scene):
    """(3,) the target (an object, a bone of an armature when target_bone names one, or the 3D cursor
    when target is None) in obj's armature space, as the scene is evaluated now."""
    return _to_armature(obj, _world_point(target, target_bone, scene))


def _world_point(target, target_bone, scene):
    """World position (3,) of the target object (or its bone's head), or of the 3D cursor when target is None."""
    if target is None:
        return np.array(scene.cursor.location, dtype=np.float64)
    if target_bone and target.type == "ARMATURE":
        head = target.pose.bones[target_bone].head
        return np.array(target.matrix_world @ head, dtype=np.float64)
    return np.array(target.matrix_world.translation, dtype=np.float64)


def _to_armature(obj, point):
    return (np.array(obj.matrix_world.inverted(), dtype=np.float64) @ np.append(point, 1.0))[:3]
