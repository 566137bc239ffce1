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

On a still rig whose constraints follow controls at rest (a control rig's deform bones copying its
unposed DRV_ twins: the bind T-pose), the gesture starts and ends in the standing pose as on any still
rig, and the constraints are held muted (`follow_rest`, `mute(hold=True)`): influence 0 on every frame
of the gesture, held beyond them as the gesture's own keys are, so the rig stands there too rather than
snapping back to the T-pose at the gesture's ends.
"""
from contextlib import contextmanager

import bpy
import numpy as np

from ..core import gesture, skeleton
from ..core.errors import RLAnimateError
from . import action_adapter

_CHAIN_TYPES = {"IK", "SPLINE_IK"}
#: The driver expression that makes a driver's F-curve a curve over the scene frame.
_FRAME_CURVE = "frame"


#: Constraints that hold a bone to another bone, whatever its parent does.
_COPYING = {"COPY_TRANSFORMS", "COPY_ROTATION", "COPY_LOCATION", "CHILD_OF", "ARMATURE"}


def held_below(obj, bone_names):
    """[(pose bone name, constraint)] of working constraints that hold a deforming bone below the named
    (keyed) bones, not itself keyed, to a bone outside them (a control rig's finger copying its DRV_ twin):
    the mesh there would not follow the gesture's keys above it."""
    keyed = set(bone_names)
    found = []
    for pose_bone in obj.pose.bones:
        if not pose_bone.constraints or pose_bone.name in keyed or not pose_bone.bone.use_deform:
            continue
        if not any(parent.name in keyed for parent in pose_bone.parent_recursive):
            continue
        for constraint in pose_bone.constraints:
            if constraint.mute or not constraint.is_valid or constraint.type not in _COPYING:
                continue
            if constraint.influence == 0.0 and influence_curve(obj, constraint) is None:
                continue
            target = getattr(constraint, "subtarget", "") if getattr(constraint, "target", None) == obj else ""
            if target not in keyed and not (target and any(
                    p.name in keyed for p in obj.pose.bones[target].parent_recursive)):
                found.append((pose_bone.name, constraint))
    return found


def against_gesture(obj, bone_names):
    """[(pose bone name, constraint)] of every constraint that keeps the gesture keyed on bone_names from
    playing: those acting on the keyed bones (`overriding`) and those holding deforming bones below them
    elsewhere (`held_below`)."""
    return overriding(obj, bone_names) + held_below(obj, bone_names)


def driven_bones(names, behaviour, arm, still=True):
    """The rig's names of the bones a gesture of `behaviour` (a behaviours.Behaviour, or None: one not known)
    keys: the action joints it owns (the other arm only made as on a still rig: gesture.owned_joints), and for
    a pointing behaviour the pointing hand."""
    canonical = list(gesture.owned_joints(arm, still))
    if behaviour is not None and behaviour.aims:
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
            if constraint.influence == 0.0 and influence_curve(obj, constraint) is None:
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


#: A message names this many constraints, then counts the rest.
NAMED = 3


def describe(found):
    """"'IK' (Inverse Kinematics) on RightHand, ... and 23 more" as a message fragment: the first NAMED
    constraints, then a count."""
    kinds = type(found[0][1]).bl_rna.properties["type"].enum_items if found else {}
    named = ", ".join(f"{constraint.name!r} ({kinds[constraint.type].name}{_target(constraint)}) on {bone}"
                      for bone, constraint in found[:NAMED])
    return named + (f" and {len(found) - NAMED} more" if len(found) > NAMED else "")


def _target(constraint):
    """', target <target>' for a constraint with a target (its bone when it has one), else ''."""
    target = getattr(constraint, "target", None)
    if target is None:
        return ""
    bone = getattr(constraint, "subtarget", "")
    return f", target {bone if bone and target.type == 'ARMATURE' else target.name}"


_ROTATIONS = ("rotation_quaternion", "rotation_euler", "rotation_axis_angle")


def drivers_on(obj, bone_names):
    """'<bone>.<channel>' of each working driver on a rotation channel of the named bones: a driver
    overrides the keys of the channel it drives."""
    data = obj.animation_data
    if data is None:
        return []
    paths = {f'pose.bones["{bpy.utils.escape_identifier(b)}"].{c}': f"{b}.{c}" for b in bone_names for c in _ROTATIONS}
    return [f"{paths[d.data_path]}[{d.array_index}]" for d in data.drivers
            if d.data_path in paths and not d.mute and d.is_valid]


def check_drivers(obj, bone_names):
    """RLAnimateError naming the drivers on rotation channels the gesture keys (`drivers_on`)."""
    found = drivers_on(obj, bone_names)
    if found:
        more = f" and {len(found) - NAMED} more" if len(found) > NAMED else ""
        raise RLAnimateError(
            f"A driver on {', '.join(found[:NAMED])}{more} overrides the rotation the gesture keys, so the bake "
            "would not play: remove the driver (right-click the channel > Delete Drivers) or mute it in the "
            "Drivers editor, and generate again.")


@contextmanager
def muted(view_layer, found):
    """Evaluate the rig with the constraints found muted (the pose the bake plays at full weight), and
    leave them as they were."""
    before = [(c, c.mute) for _, c in found]
    for constraint, _ in before:
        constraint.mute = True
    view_layer.update()
    try:
        yield
    finally:
        for constraint, state in before:
            constraint.mute = state
        view_layer.update()


def check(obj, found, start, end, mute):
    """RLAnimateError unless the constraints found may stay (none) or be muted over frames start-end."""
    if not found:
        return
    if not mute:
        several = len(found) > 1
        raise RLAnimateError(
            f"{'Constraints' if several else 'Constraint'} {describe(found)} {'override' if several else 'overrides'} "
            "the rotations the gesture keys, so the bake would not play. Click 'Generate, Muting Constraints' in "
            f"the panel (mute_constraints=True) to mute {'them' if several else 'it'} for frames {start}-{end} "
            "only, or bake the constraints into keys first (Pose > Animation > Bake Action, Visual Keying and "
            "Clear Constraints) and generate again.")
    animated = [(bone, c) for bone, c in found if not _mutable(obj, c)]
    if animated:
        raise RLAnimateError(
            f"Constraint {describe(animated)} has an animated influence, which Generate will not overwrite: "
            f"key its influence to 0 over frames {start}-{end} yourself, or turn it off, and generate again.")


def influence_curve(obj, constraint):
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
    curve = influence_curve(obj, constraint)
    return curve is None or _is_frame_curve(curve)


def _is_frame_curve(curve):
    driver = getattr(curve, "driver", None)
    return driver is not None and driver.type == "SCRIPTED" and driver.expression == _FRAME_CURVE \
        and not driver.variables and not curve.modifiers and curve.extrapolation == "CONSTANT"


def follow_rest(obj, found):
    """Whether the constraints found follow only bones of obj standing at rest: their targets, those
    bones' parents and the targets of their own constraints, recursively, each with a rest basis (a
    control rig's unposed controls). A target on another object, or a posed control, is a pose the
    animator set: the gesture then fades into and out of the pose the constraints make."""
    seen, stack = set(), [t for _, c in found for t in _targets(c)]
    while stack:
        target, bone = stack.pop()
        if target is not obj or not bone or bone not in obj.pose.bones:
            return False
        if bone in seen:
            continue
        seen.add(bone)
        pose_bone = obj.pose.bones[bone]
        if not _at_rest(pose_bone):
            return False
        if pose_bone.parent is not None:
            stack.append((obj, pose_bone.parent.name))
        stack += [t for c in pose_bone.constraints if not c.mute and c.is_valid for t in _targets(c)]
    return True


def _targets(constraint):
    """[(object, bone name or "")] the constraint follows: its target and pole target (an Armature
    constraint's targets)."""
    found = [(getattr(constraint, kind), getattr(constraint, sub, "")) for kind, sub in
             (("target", "subtarget"), ("pole_target", "pole_subtarget")) if getattr(constraint, kind, None)]
    return found + [(t.target, t.subtarget) for t in getattr(constraint, "targets", ()) if t.target is not None]


#: A basis location (in bone lengths) and scale this close to rest are at rest: float rounding.
_OFF_REST = 5e-4


def _at_rest(pose_bone):
    """Whether the bone's basis is its rest: no rotation (within gesture.AT_REST: an importer's rounding),
    location or scale (within _OFF_REST)."""
    basis = np.array(pose_bone.matrix_basis)
    rotation = np.array(pose_bone.matrix_basis.to_quaternion())
    return (np.linalg.norm(rotation[1:]) < gesture.AT_REST and np.abs(basis[:3, 3]).max() <= _OFF_REST
            * pose_bone.bone.length and np.abs(np.linalg.norm(basis[:3, :3], axis=0) - 1.0).max() < _OFF_REST)


def mute(obj, found, start, end, hold=False):
    """Mute each constraint found over frames start-end, faded with the gesture's blend (see the module);
    with hold, muted on every frame: influence 0 on the gesture's frames and on the curve's other keys
    (a later gesture's fade of a held 0, or what `unmute` gave back of a held gesture it replaces).
    Returns {influence path: {frame: its influence there before the mute}} of every frame it keyed, for
    `unmute`."""
    frames = np.arange(start, end + 1)
    # (N,) the influence's share left on each frame
    keep = np.zeros(len(frames)) if hold else 1.0 - gesture.blend_weights(len(frames))
    before = {}
    for _, constraint in found:
        curve = influence_curve(obj, constraint)
        if curve is None:
            value = constraint.influence
            curve = constraint.driver_add("influence")
            for modifier in list(curve.modifiers):  # Blender 4.2 adds a Generator, which would hide the keys
                curve.modifiers.remove(modifier)
            curve.driver.type, curve.driver.expression = "SCRIPTED", _FRAME_CURVE
            curve.extrapolation = "CONSTANT"  # 5.0 makes new driver curves linear: the ends' values hold
            kept, evaluate = {}, (lambda frame, value=value: value)
        else:
            kept, evaluate = _keys(curve), curve.evaluate
        prior = {int(f): float(evaluate(float(f))) for f in frames}
        keys = {**kept, **{f: v * k for (f, v), k in zip(prior.items(), keep, strict=True)}}
        if hold:
            prior = {**kept, **prior}
            keys = dict.fromkeys(keys, 0.0)
        before[constraint.path_from_id("influence")] = prior
        _write(curve, keys)
    return before


def unmute(obj, before):
    """Undo a replaced gesture's `mute`: before is what that mute returned. A curve no longer Generate's
    (removed, or made something else by hand) is left alone."""
    data = obj.animation_data
    for path, prior in before.items():
        curve = None if data is None else data.drivers.find(path)
        if curve is not None and _is_frame_curve(curve):
            _write(curve, {**_keys(curve), **prior})


def _keys(curve):
    """{frame: value} of the frame curve's keys."""
    return {int(round(p.co[0])): p.co[1] for p in curve.keyframe_points}


def _write(curve, keys):
    """Key the frame curve with {frame: value}, linear, in place of its keys."""
    ordered = sorted(keys)
    curve.keyframe_points.clear()
    action_adapter.write_keys(curve, np.array(ordered, dtype=np.float64), np.array([keys[f] for f in ordered]))
