"""Bone constraints that would override a gesture's keys, and muting them for the gesture's frames.

A constraint on a keyed bone (an IK chain through it, Copy Rotation, Child Of, ...) replaces the
rotation the gesture keys, so the bake would not play. Generate refuses, or, asked to, mutes each
such constraint over the gesture's frames only, with a driver on its influence:
`<influence> * ((frame < start) + (frame > end))`, one factor per gesture, so the constraint works as
before everywhere else. Keys and drivers are the only per-frame mechanism that NLA strips outside
their frames cannot leave stuck at the last value they set.
"""
import re

from ..core import gesture, skeleton
from ..core.errors import RLAnimateError
from . import action_adapter

_CHAIN_TYPES = {"IK", "SPLINE_IK"}
#: The driver expression a previous Generate put on an influence (a value times frame-range factors).
_MUTE_EXPRESSION = re.compile(r"[-+0-9.e]+( \* \(\(frame < -?\d+\) \+ \(frame > -?\d+\)\))+")


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
    """Whether the influence is static, or driven by an earlier Generate's mute."""
    curve = _influence_curve(obj, constraint)
    return curve is None or (getattr(curve, "driver", None) is not None
                             and _MUTE_EXPRESSION.fullmatch(curve.driver.expression) is not None)


def mute(obj, found, start, end):
    """Mute each constraint found over frames start-end with a driver on its influence (see the module)."""
    for _, constraint in found:
        curve = _influence_curve(obj, constraint)
        if curve is None:
            curve = constraint.driver_add("influence")
            curve.driver.type = "SCRIPTED"
            curve.driver.expression = f"{constraint.influence:.6g}"
        curve.driver.expression += f" * ((frame < {start}) + (frame > {end}))"
