"""Bone constraints that would override a gesture's keys, and muting them for the gesture's frames.

A constraint on a keyed bone (an IK chain through it, Copy Rotation, Child Of, ...) replaces the
rotation the gesture keys, so the bake would not play. Generate refuses, or, asked to, mutes each
such constraint over the gesture's frames only, fading it out as the gesture blends in and back in as
it blends out: on every frame f of the gesture its influence is multiplied by 1 - w(f), w the
gesture's blend weight (`gesture.blend_weights`). The values sit as linear keys on the F-curve of a
driver whose expression is `frame`, so the influence follows the scene frame whatever the NLA does
(a key on an NLA strip would leave the influence stuck at its last value outside the strip's frames),
later gestures multiply in over their own frames, and it shows as an editable curve in the Drivers
editor. Outside the gestures the constraint works as before, and at their ends the pose is the one
the constraint made, so nothing jumps.
"""
import numpy as np

from ..core import gesture, skeleton
from ..core.errors import RLAnimateError
from . import action_adapter

_CHAIN_TYPES = {"IK", "SPLINE_IK"}
#: The driver expression that makes a driver's F-curve a curve over the scene frame.
_FRAME_CURVE = "frame"


def driven_bones(names, behaviour, arm):
    """The rig's names of the bones a gesture keys: the action joints, and for Point the pointing hand."""
    canonical = list(skeleton.ACTION_JOINTS)
    if behaviour == "POINT":
        canonical += [skeleton.ARM_PREFIX[arm] + bone for bone in gesture.POINTING_HAND]
    return [names[name] for name in canonical if name in names]


def overriding(obj, bone_names):
    """[(pose bone name, constraint)] of the constraints that act on any of the armature's bone_names."""
    driven = set(bone_names)
    found = []
    for pose_bone in obj.pose.bones:
        for constraint in pose_bone.constraints:
            if constraint.mute or not constraint.is_valid:
                continue
            if constraint.influence == 0.0 and _influence_curve(obj, constraint) is None:
                continue
            if driven & set(_acted_on(pose_bone, constraint)):
                found.append((pose_bone.name, constraint))
    return found


def _acted_on(pose_bone, constraint):
    """Bones the constraint moves: an IK chain's bones (chain_count 0: up to the root), else its owner."""
    if constraint.type not in _CHAIN_TYPES:
        return [pose_bone.name]
    chain = [pose_bone] + list(pose_bone.parent_recursive)
    count = constraint.chain_count
    return [bone.name for bone in (chain[:count] if count else chain)]


def describe(found):
    """'IK' on RightHand, ... as a message fragment."""
    kinds = type(found[0][1]).bl_rna.properties["type"].enum_items if found else {}
    return ", ".join(f"{constraint.name!r} ({kinds[constraint.type].name}) on {bone}" for bone, constraint in found)


def check(obj, found, start, end, mute):
    """RLAnimateError unless the constraints found may stay (none) or be muted over frames start-end."""
    if not found:
        return
    if not mute:
        raise RLAnimateError(
            f"Constraint {describe(found)} overrides the rotations the gesture keys, so the bake would not "
            f"play. Click 'Generate, Muting Constraints' in the panel (mute_constraints=True) to mute it "
            f"for frames {start}-{end} only, or bake the constraint into keys first (Pose > Animation > "
            f"Bake Action, Visual Keying and Clear Constraints) and generate again.")
    animated = [(bone, c) for bone, c in found if not _mutable(obj, c)]
    if animated:
        raise RLAnimateError(
            f"Constraint {describe(animated)} has an animated influence, which Generate will not overwrite: "
            f"key its influence to 0 over frames {start}-{end} yourself, or turn it off, and generate again.")


def _influence_curve(obj, constraint):
    """The driver or F-curve of the active action that animates the constraint's influence, or None."""
    path = constraint.path_from_id("influence")
    data = obj.animation_data
    if data is None:
        return None
    driver = data.drivers.find(path)
    if driver is not None:
        return driver
    target = action_adapter.active_target(obj)
    targets = ([target] if target is not None else []) + action_adapter.strip_targets(obj)
    return next((f for t in targets for f in t.fcurves() if f.data_path == path), None)


def _mutable(obj, constraint):
    """Whether the influence is static, or a frame curve of an earlier Generate's mute."""
    curve = _influence_curve(obj, constraint)
    return curve is None or _is_frame_curve(curve)


def _is_frame_curve(curve):
    driver = getattr(curve, "driver", None)
    return driver is not None and driver.type == "SCRIPTED" and driver.expression == _FRAME_CURVE \
        and not driver.variables and not curve.modifiers and curve.extrapolation == "CONSTANT"


def mute(obj, found, start, end):
    """Mute each constraint found over frames start-end, faded with the gesture's blend (see the module)."""
    frames = np.arange(start, end + 1)
    keep = 1.0 - gesture.blend_weights(len(frames))  # (N,) the influence's share left on each frame
    for _, constraint in found:
        curve = _influence_curve(obj, constraint)
        if curve is None:
            value = constraint.influence
            curve = constraint.driver_add("influence")
            for modifier in list(curve.modifiers):  # Blender 4.2 adds a Generator, which would hide the keys
                curve.modifiers.remove(modifier)
            curve.driver.type, curve.driver.expression = "SCRIPTED", _FRAME_CURVE
            curve.extrapolation = "CONSTANT"  # 5.0 makes new driver curves linear: the ends' values hold
            kept, evaluate = {}, (lambda frame, value=value: value)
        else:
            kept, evaluate = {int(round(p.co[0])): p.co[1] for p in curve.keyframe_points}, curve.evaluate
        keys = {f: v for f, v in kept.items() if not start <= f <= end}
        keys.update({int(f): evaluate(float(f)) * k for f, k in zip(frames, keep)})
        ordered = sorted(keys)
        curve.keyframe_points.clear()
        action_adapter.write_keys(curve, np.array(ordered, dtype=np.float64), np.array([keys[f] for f in ordered]))
