"""Verify a bake plays: the mesh's hand and finger go where the gesture put them, or the bake is undone.

After Generate writes its keys, the rig is evaluated as Blender plays it (scene.frame_set, the
depsgraph's evaluated pose) at three of the gesture's frames (core.bake_measure.check_frames), and
the bones the mesh deforms with are measured: the bones with Deform on that name a vertex group of a
mesh whose Armature modifier uses the rig (every deforming bone on a rig without a skinned mesh).
Each measured role bone (the hand, the first and last index bone) is stood in for by the deformed
bone that rests where it does: the role bone itself when it deforms, else the deform bone whose rest
head and tail are nearest (Rigify's DEF-hand.R for hand_fk.R, an export skeleton's bone copying it).

When the deformed wrist is more than 2 cm from where the gesture put it, or the finger line more than
3 degrees off, or a Point target moved with the gesture, `BakeUndo.restore` puts back exactly what the
bake changed (actions, NLA tracks, muted constraints' influence, the pose, the scene frame) and the
error names the bone and what drives it.
"""
import bpy
import numpy as np

from ..core import bake_measure
from ..core.errors import RLAnimateError
from . import action_adapter, armature_io, constraints

#: A role bone whose evaluated rotation or head differs from the plan by more than these plays no keys
#: of its own: something overrides it.
_OVERRIDE_DEG, _OVERRIDE_SHARE = 1.0, 0.01


class BakeUndo:
    """What a bake changes on one armature, recorded before it writes, and `restore` to put it back."""

    def __init__(self, obj, found, switches=()):
        data = obj.animation_data
        self.obj, self.had_data = obj, data is not None
        self.action = data.action if data else None
        self.slot = data.action_slot if data is not None and action_adapter.LAYERED else None
        self.tracks = {t.as_pointer() for t in data.nla_tracks} if data else set()
        self.actions = {a.as_pointer() for a in bpy.data.actions}
        self.influences = [(c, c.influence, _saved_keys(constraints.influence_curve(obj, c))) for _, c in found]
        self.channels = {path: _channel_values(obj.pose.bones, path, size) for path, size in _CHANNELS.items()}
        self.properties = [(pb, key, pb[key]) for pb, key in switches]

    def restore(self):
        """Put back the animation data, the constraints' influence and the pose as recorded."""
        obj = self.obj
        data = obj.animation_data
        if data is not None:
            for track in [t for t in data.nla_tracks if t.as_pointer() not in self.tracks]:
                data.nla_tracks.remove(track)
            data.action = self.action
            if self.slot is not None:
                data.action_slot = self.slot
        for constraint, influence, keys in self.influences:
            curve = constraints.influence_curve(obj, constraint)
            if keys is None:
                if curve is not None:
                    constraint.driver_remove("influence")
            else:
                _restore_keys(curve, keys)
            constraint.influence = influence
        if not self.had_data and obj.animation_data is not None:
            obj.animation_data_clear()
        for action in [a for a in bpy.data.actions if a.as_pointer() not in self.actions]:
            bpy.data.actions.remove(action)
        for k, pose_bone in enumerate(obj.pose.bones):
            for path, values in self.channels.items():
                setattr(pose_bone, path, tuple(values[k]))
        for pose_bone, key, value in self.properties:
            pose_bone[key] = value


#: The pose channels a bake may change, with their sizes.
_CHANNELS = {"location": 3, "rotation_quaternion": 4, "rotation_euler": 3, "rotation_axis_angle": 4, "scale": 3}
_KEY_FIELDS = ("co", "handle_left", "handle_right", "interpolation", "handle_left_type", "handle_right_type")


def _channel_values(pose_bones, path, size):
    """(P, size) float32 values of channel `path` of every pose bone, in their order, read at once."""
    values = np.empty((len(pose_bones), size), dtype=np.float32)
    pose_bones.foreach_get(path, values.ravel())
    return values


def _saved_keys(curve):
    if curve is None:
        return None
    return [tuple(tuple(v) if hasattr(v, "__len__") and not isinstance(v, str) else v
                  for v in (getattr(p, f) for f in _KEY_FIELDS)) for p in curve.keyframe_points]


def _restore_keys(curve, keys):
    curve.keyframe_points.clear()
    curve.keyframe_points.add(len(keys))
    for point, values in zip(curve.keyframe_points, keys, strict=True):
        for field, value in zip(_KEY_FIELDS, values, strict=True):
            setattr(point, field, value)


def deformed_bones(obj):
    """Names of the bones the rig's skinned meshes deform with: Deform on and a vertex group of a mesh
    whose Armature modifier uses the rig; every Deform bone when no mesh is skinned to it."""
    deforming = {b.name for b in obj.data.bones if b.use_deform}
    groups = set()
    for mesh in bpy.data.objects:
        if mesh.type == "MESH" and any(m.type == "ARMATURE" and m.object == obj and m.use_vertex_groups
                                       for m in mesh.modifiers):
            groups |= {g.name for g in mesh.vertex_groups}
    skinned = deforming & groups
    return skinned or deforming


def stand_in(obj, bone, deformed):
    """The deformed bone that carries role bone `bone`: itself when it deforms, else the deformed bone
    resting nearest it (heads and tails within half its length), else the bone itself."""
    if bone in deformed:
        return bone
    bones = obj.data.bones
    rest, names = bones[bone], list(deformed)
    if not names:
        return bone
    heads, tails = (np.array([getattr(bones[n], end) for n in names]) for end in ("head_local", "tail_local"))
    gaps = (np.linalg.norm(heads - np.array(rest.head_local), axis=1)
            + np.linalg.norm(tails - np.array(rest.tail_local), axis=1))  # (D,)
    nearest = int(np.argmin(gaps))
    return names[nearest] if gaps[nearest] < 0.5 * rest.length else bone


def _armature_matrices(obj, names):
    """(P, 4, 4) evaluated armature-space pose matrices of the named bones (the depsgraph's pose)."""
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    return np.array([evaluated.pose.bones[n].matrix for n in names], dtype=np.float64)


def _rest_matrices(obj, names):
    return np.array([obj.data.bones[n].matrix_local for n in names], dtype=np.float64)


def verify(scene, plan):
    """RLAnimateError when the baked plan does not play: the deformed hand or finger off the plan, or the
    target of a target behaviour (Point) that moves with the gesture. plan: generate._Plan after its write."""
    obj, made, arm = plan.obj, plan.gesture, plan.settings.arm
    rig = made.rig
    pose = bake_measure.planned_pose(rig, arm, made.bones, made.keyed)  # (N, B, 4, 4)
    planned = bake_measure.planned_points(rig, arm, pose)  # (N, 3, 3)
    measured = bake_measure.measured_bones(rig.roles, arm)
    deformed = deformed_bones(obj)
    carriers = [stand_in(obj, bone, deformed) for bone in measured]
    scale = float(np.cbrt(abs(np.linalg.det(np.array(obj.matrix_world.to_3x3())))))
    rest_points, carrier_rests = bake_measure.rest_points(rig, arm), _rest_matrices(obj, carriers)
    start = int(plan.settings.start_frame)
    for index in bake_measure.check_frames(len(made.keyed), planned[:, 0], plan.request.shown):
        frame = start + index
        scene.frame_set(frame)
        played = bake_measure.carried(_armature_matrices(obj, carriers)[None], carrier_rests, rest_points)
        distance, angle = (float(v[0]) for v in bake_measure.misses(planned[index:index + 1], played, scale))
        if distance > bake_measure.HAND_TOLERANCE or angle > bake_measure.FINGER_TOLERANCE_DEG:
            cause = _cause(obj, rig, pose[index], measured, carriers, made.bones)
            raise RLAnimateError(
                f"The bake of {obj.name!r} would not play, so it was undone: at frame {frame} the hand the mesh "
                f"deforms with ({carriers[0]}) is {100 * distance:.1f} cm from where the gesture puts it and its "
                f"finger {angle:.1f} degrees off. {cause}")
        if made.targets is not None:
            _check_target(obj, made, frame, made.targets[index], scale)


def _check_target(obj, made, frame, sampled, scale):
    """RLAnimateError when the target (of Point or another target behaviour), evaluated at frame after the
    bake, left where it was read."""
    now = armature_io.target_point(obj, made.target, made.target_bone, bpy.context.scene)
    moved = float(np.linalg.norm(now - sampled)) * scale
    if moved > bake_measure.HAND_TOLERANCE:
        what = repr(made.target.name) + (f" bone {made.target_bone!r}" if made.target_bone else "")
        raise RLAnimateError(
            f"The bake of {obj.name!r} was undone: the target {what} moves with the gesture ({100 * moved:.1f} cm at "
            f"frame {frame}; it is, or hangs from, a bone the gesture turns), so the finger would point where the "
            "target was, not where it goes. Point at something the gesture does not move: another object, or a "
            "bone of another armature.")


def _cause(obj, rig, planned, measured, carriers, keyed):
    """Why the deformed hand is off, naming the bone and what drives it, with the fix."""
    evaluated = dict(zip(rig.skeleton.names, _armature_matrices(obj, rig.skeleton.names), strict=True))
    size = float(np.linalg.norm(rig.skeleton.rest_head(measured[0]) - rig.skeleton.rest_head(rig.skeleton.names[0])))
    for i in rig.skeleton.ancestors(measured[0]) + [rig.skeleton.index[b] for b in measured[1:]]:
        name = rig.skeleton.names[i]
        off = bake_measure.turned(evaluated[name], planned[i]) > _OVERRIDE_DEG or np.linalg.norm(
            evaluated[name][:3, 3] - planned[i, :3, 3]) > _OVERRIDE_SHARE * size
        if off:
            return f"The bone {name} does not play the gesture: {_drivers(obj, name, keyed)}"
    for bone, carrier in zip(measured, carriers, strict=True):
        if carrier != bone:
            return (f"The mesh deforms with {carrier}, which does not follow {bone}, the bone the gesture keys: "
                    f"{_drivers(obj, carrier, keyed, bone)}")
    return f"{measured[0]} plays the gesture but the mesh's bones do not follow it: {_MAP_ROLES}."


_MAP_ROLES = ("map the roles to the bones the mesh deforms with in a bone-map file (Save Bone Map, edit, pick "
              "it as Bone Map)")


def _drivers(obj, name, keyed, follow=None):
    """What moves bone `name` besides its keys, with the fix: its constraints, a driver on it, or its
    parent. follow: the keyed bone a deformed bone should follow (None for a keyed bone itself)."""
    acting = constraints.overriding(obj, [name])
    if acting and follow is None:
        return (f"{constraints.describe(acting)} drives it. Click 'Generate, Muting Constraints' to mute "
                "them over the gesture's frames, or bake them into keys (Pose > Animation > Bake Action, Visual "
                "Keying and Clear Constraints) and generate again.")
    if acting:
        return f"{constraints.describe(acting)} drives it. Make it follow {follow}, or {_MAP_ROLES}."
    driven = constraints.drivers_on(obj, [name])
    if driven:
        return f"a driver ({driven[0]}) drives it: remove or mute it in the Drivers editor and generate again."
    parent = obj.pose.bones[name].parent
    if parent is not None and parent.name not in keyed:
        return (f"it follows its parent {parent.name}, which the gesture does not key: "
                f"{_drivers(obj, parent.name, keyed, follow)}")
    return f"nothing the gesture keys moves it: {_MAP_ROLES}."
