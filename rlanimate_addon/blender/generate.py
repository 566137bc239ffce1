"""Generate Gesture: run the agent for the scene's settings and bake the result onto the selected armatures.

On an armature with gestures a Generate either bakes one of them again in place (the one selected in the
panel's list, else the one on the same arm that starts on the same frame) or adds one (core/composition.py):
over an earlier gesture on its arm that still plays at its start it takes over there, starting from that
gesture's pose, which is trimmed there; before a later one it is trimmed where that one takes over. Then the
gestures that depend on the one it changed (their aim, their start pose) are baked again from their records,
unless edited by hand. blender/gestures.py describes how a gesture's keys are laid out.
"""
import contextlib
import dataclasses
import types
from collections.abc import Sequence
from typing import Any

import bpy
import numpy as np

from ..core import (
    behaviours,
    blas_threads,
    channels,
    composition,
    frame_rate,
    gesture,
    key_reduction,
    rig_roles,
    rig_scale,
)
from ..core import rigify as rig_rigify
from ..core.errors import RLAnimateError
from . import (
    action_adapter,
    armature_io,
    bake_check,
    constraints,
    gestures,
    key_layers,
    playback,
    pose_underneath,
    preferences,
    properties,
    rigify,
)
from .gestures import MAIN, TORSO


def _check_request(settings, agent):
    """RLAnimateError when the agent does not perform the behaviour, or a target behaviour (Point) has no
    target, or a target bone its target armature lacks."""
    if settings.behaviour not in agent.behaviours:
        performs = ", ".join(behaviours.title(b) for b in agent.behaviours)
        asked = f"no {behaviours.title(settings.behaviour)}" if settings.behaviour else "not the behaviour chosen"
        raise RLAnimateError(f"The selected agent performs {performs}, {asked}: pick one of its behaviours in "
                             "the panel, or choose an agent trained for it in Preferences > Add-ons > RLAnimate.")
    if agent.kind(settings.behaviour) != behaviours.TARGET:
        return
    if settings.target is None and not settings.use_cursor:
        raise RLAnimateError(f"{behaviours.title(settings.behaviour)} needs a target: pick a target object, or "
                             "tick 'Use 3D Cursor'.")
    target, bone = settings.target, target_bone(settings)
    if bone and bone not in target.pose.bones:
        raise RLAnimateError(f"The target {target.name!r} has no bone {bone!r}: pick one of its bones, "
                             "or clear Target Bone to point at the object itself.")


def target_bone(settings):
    """The bone of the target armature to point at, or "": Target Bone is kept, unused and hidden in the
    panel, while the target is not an armature."""
    target = settings.target
    return settings.target_bone if target is not None and target.type == "ARMATURE" else ""


#: Blender's frame range: keys outside it cannot be played or reached.
_FRAMES = bpy.types.Scene.bl_rna.properties["frame_current"]


def check_keepable(obj):
    """RLAnimateError when the armature cannot keep a new action: linked from a library, or not editable."""
    if obj.library is not None:
        raise RLAnimateError(f"Armature {obj.name!r} is linked from {obj.library.filepath}, so a gesture baked "
                             "onto it would be lost when the file is saved. Make a library override (Object > "
                             "Library Override > Make) or make it local (Object > Relations > Make Local), and "
                             "generate on that.")
    if not obj.is_editable:
        raise RLAnimateError(f"Armature {obj.name!r} is a library override that cannot be edited, so it cannot "
                             "keep a gesture: make the override editable (Outliner: Library Override > Make "
                             "Editable) and generate again.")


def check_not_editing(obj):
    """RLAnimateError when the armature is in Edit mode, where its pose does not play (the bake check failed
    there). Refused rather than left and returned to: the undo step Blender pushes in Edit mode is an Edit-mode
    step, and that it takes back a gesture's action cannot be checked headless (ed.undo needs a window)."""
    if obj.mode == "EDIT":
        raise RLAnimateError(f"Armature {obj.name!r} is in Edit mode, where its pose does not play: leave Edit mode "
                             "(Tab, or choose Pose Mode) and generate again.")


def check_inherited_rotation(obj, roles):
    """RLAnimateError when a bone playing a role does not inherit its parent's rotation: the gesture's
    retargeting and aim turn each bone relative to its parent."""
    loose = [bone for bone in roles.values() if not obj.data.bones[bone].use_inherit_rotation]
    if loose:
        raise RLAnimateError(f"Bone {loose[0]!r} of {obj.name!r} does not inherit its parent's rotation (Bone "
                             "Properties > Relations > Inherit Rotation is off), and the gesture turns each bone "
                             "relative to its parent: turn Inherit Rotation on for it, or map another bone to its "
                             "role with a bone-map file.")


def check_nla(obj):
    """RLAnimateError when the armature's NLA would not play a new gesture track: a strip in tweak mode,
    or a soloed track (only it plays)."""
    data = obj.animation_data
    if data is None:
        return
    if data.use_tweak_mode:
        raise RLAnimateError(f"{obj.name!r} is in NLA tweak mode (editing a strip's action), where no new strip "
                             "can be added: leave tweak mode (NLA editor: Tab) and generate again.")
    soloed = [track.name for track in data.nla_tracks if track.is_solo]
    if soloed:
        raise RLAnimateError(f"The NLA track {soloed[0]!r} of {obj.name!r} is soloed, so only it plays and the "
                             "gesture's track would not: un-solo it (the star in the NLA editor) and generate again.")


def check_frames(start, frame_count):
    """RLAnimateError when the gesture's frames leave Blender's frame range."""
    low, high = _FRAMES.hard_min, _FRAMES.hard_max
    if start < low or start + frame_count - 1 > high:
        raise RLAnimateError(f"Frames {start}-{start + frame_count - 1} leave Blender's frame range "
                             f"({low} to {high}), where keys cannot play: set a start frame from {low} to "
                             f"{high - frame_count + 1}.")


def selected_armatures(context, settings):
    """The armatures to bake onto: the active object's (itself, or the armature deforming a selected mesh),
    then every other selected object's (the Point target excluded)."""
    active = properties.armature_of(context.active_object)
    if active is None:
        raise RLAnimateError("The active object is not an armature, nor a mesh an armature deforms: select the "
                             "character's armature or its mesh.")
    found = [active]
    for obj in context.selected_objects:
        rig = properties.armature_of(obj)
        if rig is not None and rig not in found and rig is not settings.target and obj is not settings.target:
            found.append(rig)
    return found


@dataclasses.dataclass(frozen=True)
class _Armature:
    """The armature checked for the gesture: its bones' roles, and the constraints the gesture mutes."""
    obj: Any
    family: str  # its bone naming (rig_roles)
    roles: dict[str, str]  # {role: bone}
    overriding: list  # the constraints that would override the gesture (constraints.against_gesture)
    ik_share: Any  # a Rigify arm in IK: its IK_FK value, switched to FK over the gesture; else None


@dataclasses.dataclass(frozen=True)
class _Request:
    """What Generate is asked, and what it does to the armature's other gestures."""
    settings: Any  # the panel's settings (properties.settings_for) or a gesture's recorded ones
    still: bool  # made as on a still rig: the rig's base (blender/gestures.py)
    previous: Any = None  # the gesture it bakes again in place (gestures.Placed), or None: a new one
    before: Any = None  # ... and that gesture's Span before
    taken: Any = None  # the earlier gesture on its arm it takes over from (trimmed at its start), or None
    taking: Any = None  # the Span of the later gesture on its arm that takes over from it, or None
    preview: str = ""  # baked while Follow Target drags its target: GESTURE or AIM (`bake`)

    @property
    def frames(self) -> tuple[int, int]:
        """(first, last) frame of the gesture."""
        start = int(self.settings.start_frame)
        return start, start + int(self.settings.frame_count) - 1

    @property
    def shown(self) -> int:
        """Frames from its start the gesture plays at full influence: all, or up to where a later one on its
        arm takes over."""
        start, end = self.frames
        return end - start + 1 if self.taking is None else min(end, self.taking.start) - start + 1


@dataclasses.dataclass(frozen=True)
class _Gesture:
    """The gesture made for a request on an armature, ready to write."""
    rig: gesture.RigState  # the rig as the gesture is made over it
    bones: Sequence[str]  # the bones it keys, in the columns of `keyed`
    keyed: np.ndarray  # (N, B, 4) their local quaternions as the gesture plays them
    keys: dict  # {MAIN: keys, TORSO: keys} (key_layers.key_action's)
    blend_type: str  # of its main layer
    worst: float  # editable keys: the worst deviation of the reduced keys (degrees)
    hold: bool  # the constraints it mutes stay muted beyond its frames (constraints.follow_rest)
    under: dict  # {bone: channel values} of keyed bones that stand still underneath
    from_ik: bool  # a Rigify arm standing in IK (IK_FK below 1) on any of the gesture's frames
    properties: Any = None  # a Rigify arm in IK: its IK_FK switch keys (rigify.switch_keys)
    target: Any = None  # a target behaviour's target object, or None (none, or the 3D cursor)
    target_bone: str = ""  # ... its bone
    targets: Any = None  # ... (N, 3) where it was read on each frame


@dataclasses.dataclass(frozen=True)
class _Checked:
    """A request checked on an armature."""
    request: _Request
    armature: _Armature

    @property
    def obj(self) -> Any:
        return self.armature.obj

    @property
    def settings(self) -> Any:
        return self.request.settings

    @property
    def frames(self) -> tuple[int, int]:
        return self.request.frames


@dataclasses.dataclass(frozen=True)
class _Plan(_Checked):
    """A checked request and the gesture made for it, ready to write."""
    gesture: _Gesture


def _check(obj, settings, start, end, mute_constraints, still):
    """The checked _Armature; RLAnimateError when it cannot take the gesture."""
    check_not_editing(obj)
    family, roles = armature_io.rig_roles_of(obj, settings.bone_map_file)
    rig_roles.check_roles(obj.name, roles, settings.arm, family)
    ik_share = rigify.ik_share(obj, settings.arm) if family == rig_roles.RIGIFY.name else None
    check_keepable(obj)
    check_nla(obj)
    check_inherited_rotation(obj, roles)
    armature_io.check_hips(obj, roles)
    declared = properties.declared_behaviour(bpy.context, settings.behaviour)
    driven = constraints.driven_bones(roles, declared, settings.arm, still)
    rig_scale.check_nonzero_scale(obj.name, obj.matrix_world, _scales(obj, driven))
    # Eyes the rig already aims with constraints (a Damped Track to an eye target) stay the rig's.
    roles = {role: bone for role, bone in roles.items()
             if not (role.endswith("Eye") and len(obj.pose.bones[bone].constraints))}
    driven = constraints.driven_bones(roles, declared, settings.arm, still)
    constraints.check_drivers(obj, driven)
    overriding = constraints.against_gesture(obj, driven)
    constraints.check(obj, overriding, start, end, mute_constraints)
    return _Armature(obj, family, roles, overriding, ik_share)


def _plan(obj, settings, selected, mute_constraints, preview):
    """The request of a gesture on an armature checked (_Checked), and what it does to the armature's other
    gestures: the one it bakes again (`selected`: a gesture's name, else the one on its arm starting on its frame),
    the one it takes over from and the one taking over from it (none with Keep Previous: it layers)."""
    start = int(settings.start_frame)
    end = start + int(settings.frame_count) - 1
    placed = gestures.placed_gestures(obj)
    spans = [g.span for g in placed]
    named = {g.name: g for g in placed}
    match = composition.regenerated(spans, settings.arm, start, selected, settings.keep_previous)
    previous = None if match is None else named[match.id]
    still = previous.still if previous is not None else not action_adapter.is_animated(obj)
    armature = _check(obj, settings, start, end, mute_constraints, still)
    request = _Request(settings, still, previous, previous.span if previous is not None else None, preview=preview)
    if previous is not None:
        _check_unedited(previous, settings, "bake it again")
    if (previous is not None and previous.span.layered) or settings.keep_previous:
        return _Checked(request, armature)
    exclude = () if previous is None else (previous.name,)
    taken = composition.taken_over(spans, settings.arm, start, exclude)
    request = dataclasses.replace(request, taken=None if taken is None else named[taken.id],
                                  taking=composition.taking_over(spans, settings.arm, start, end, exclude))
    if request.taken is not None and request.taken.still:  # a base fades its own keys: its edits would be lost
        _check_unedited(request.taken, settings, "take over from it at frame {start}, fading its keys",
                        skip=request.taken.other_arm_curves())
    return _Checked(request, armature)


def _check_unedited(placed, settings, doing, skip=()):
    """RLAnimateError naming the bones and frames of the gesture's keys edited by hand (but those of `skip`),
    unless Replace Edited Keys is on."""
    if getattr(settings, "replace_edited_keys", False):
        return
    found = {channel: frames for channel, frames in gestures.edited(placed).items() if channel not in skip}
    if found:
        raise RLAnimateError(
            f"The keys of {placed.name!r} were edited by hand on {gestures.describe_edits(found)}, and Generate "
            f"would {doing.format(start=int(settings.start_frame))}, overwriting them: tick 'Replace Edited Keys' "
            "to do so anyway, or 'Keep Previous' to layer the new gesture over it instead.")


def _scales(obj, names):
    """{bone: its pose scale (3,)} of the named bones and their parents, each read once (bone, parents, next
    bone ...)."""
    scales = {}
    for name in names:
        bone = obj.pose.bones[name]
        while bone is not None and bone.name not in scales:  # a bone read before had its parents read too
            scales[bone.name] = tuple(bone.scale)
            bone = bone.parent
    return scales


def _compute(context, plan, agent, frames):
    """The checked plan with its gesture and keys made (_Plan; nothing written), on one BLAS thread: every product
    here is small, and on a machine with busy cores BLAS threads only wait (core/blas_threads.py)."""
    with blas_threads.single_blas_thread():
        scene, settings = context.scene, plan.settings
        original_frame = scene.frame_current
        targeted = agent.kind(settings.behaviour) == behaviours.TARGET
        target = settings.target if targeted else None
        bone = target_bone(settings) if target else ""
        try:
            rig, below_values, targets, switch = _read_once(context, plan, frames, target, bone)
        finally:
            if scene.frame_current != original_frame:
                scene.frame_set(original_frame)
        request = gesture.GestureRequest(settings.behaviour, settings.arm, len(frames),
                                         targets=targets if targeted else None,
                                         exaggeration=settings.exaggeration, seed=settings.seed or None,
                                         tempo=settings.tempo or None, exact_aim=settings.exact_aim,
                                         fps=properties.scene_fps(scene))
        bones, keyed, below = _rotations(agent, request, rig, plan, frames)
        aim = {"target": target, "target_bone": bone, "targets": targets} if target is not None else {}
        return _made(plan, rig, bones, keyed, below, below_values, switch, aim)


def _made(plan, rig, bones, keyed, below, below_values, switch, aim):
    """The _Plan of the checked plan and its gesture's rotations over the rig: its keys and what they mute."""
    obj, still, overriding = plan.obj, plan.request.still, plan.armature.overriding
    blend_type = "REPLACE" if still else plan.settings.blend_type
    # A still rig held at rest by its constraints stands as any still rig does: they stay muted.
    hold = bool(overriding) and still and constraints.follow_rest(obj, overriding)
    switch_keys = None
    if plan.armature.ik_share is not None:
        switch_keys = rigify.switch_keys(obj, plan.settings.arm, switch, blend_type, rig.animated)
    under = {bone: below_values[bone][0] for bone in bones if not np.ptp(below_values[bone], axis=0).any()}
    if rig.resting:  # a base keeps where its bones first stood, whatever gestures above move them since
        under.update({bone: values for bone, values in plan.request.previous.record["under"].items()
                      if bone in rig.resting and bone in bones})
    keys, worst = _keys(plan, bones, keyed, blend_type, below, below_values)
    made = _Gesture(rig, bones, keyed, keys, blend_type, worst, hold, under,
                    from_ik=switch is not None and bool(np.any(switch < 1.0)), properties=switch_keys, **aim)
    return _Plan(plan.request, plan.armature, made)


#: The rig as a Follow Target drag's first re-bake read it, for the drag's other re-bakes (`bake`'s preview):
#: {_read_key: (RigState, rotation values, IK_FK or None)}; and the gesture it last baked before its aim
#: ({_read_key: gesture.Blended}), which a preview of the aim alone aims again.
_reads: dict = {}
_blends: dict = {}


def forget_reads():
    """Forget the reads and gestures Follow Target's previews reuse (`_reads`, `_blends`)."""
    _reads.clear()
    _blends.clear()


def _rotations(agent, request, rig, plan, frames):
    """gesture.gesture_rotations' result; in a preview of the aim alone, the gesture the drag baked last, aimed
    at the request's targets (the agent not run again)."""
    key = _read_key(plan, frames)
    blended = _blends.get(key) if plan.request.preview == AIM else None
    if blended is None:
        blended = gesture.blended_gesture(agent, request, rig)
    if plan.request.preview:
        _blends[key] = blended
    return gesture.aimed(request, rig, blended)


def _read_key(plan, frames):
    previous = plan.request.previous.name if plan.request.previous is not None else ""
    return (plan.obj.as_pointer(), previous, int(frames[0]), len(frames), plan.settings.arm, plan.settings.behaviour,
            tuple(sorted(plan.armature.roles.items())), tuple(bone for bone, _ in plan.armature.overriding))


def _read_once(context, plan, frames, target, bone):
    """`_read_rig`'s result (the caller sets the gesture baked again aside). In a preview, the rig as the drag's
    first re-bake read it, the target where it is now, where neither the rig nor the target can move."""
    obj, key = plan.obj, _read_key(plan, frames)
    if plan.request.preview and key in _reads:  # kept only where neither moves
        rig, values, switch = _reads[key]
        point = armature_io.target_point(obj, target, bone, context.scene)
        return rig, values, np.broadcast_to(point, (len(frames), 3)), switch
    rig, values, targets, switch = _read_rig(context, plan, frames, target, bone)
    still = not armature_io.may_move(obj) and (target is None or not armature_io.may_move(target)) and not (
        bone and action_adapter.is_animated(target))
    if plan.request.preview and still:
        _reads[key] = (rig, values, switch)
    return rig, values, targets, switch


def _read_rig(context, plan, frames, target, bone):
    """(the RigState as the gesture is made over it, {bone: (N, C) rotation values underneath}, (N, 3) targets, a
    Rigify arm's (N,) IK_FK underneath or None): each frame played once, with the constraints the gesture mutes
    off (the pose it plays over, which Exact Aim solves on). A Rigify arm's ORG- bones are read in the same pass,
    unless constraints are muted: then as the rig plays with them, in a pass of their own."""
    obj, arm, armature = plan.obj, plan.settings.arm, plan.armature
    rigify_arm = rigify.arm_reads(arm) if armature.ik_share is not None else ((), ())
    alongside = rigify_arm if not armature.overriding else ((), ())
    with constraints.muted(context.view_layer, armature.overriding):
        rig, values, targets, played = armature_io.sample_rig(context, obj, armature.roles, armature.family, frames,
                                                              target, bone, *alongside)
    rig = _as_made(plan, rig, values, frames)
    if armature.ik_share is None:
        return rig, values, targets, None
    if armature.overriding:
        played = armature_io.sample_rig(context, obj, armature.roles, armature.family, frames, None, "",
                                        *rigify_arm)[3]
    controls, switch = rigify.played_arm(arm, played)
    return rig_rigify.snap_fk(rig, rig_rigify.fk_controls(arm), controls), values, targets, switch


def _as_made(plan, rig, values, frames):
    """The rig as the gesture is made over it (gesture.RigState's still, held, resting and bare): as on a still
    rig for the rig's base, whose bones that nothing but gestures move start where it first found them (so it
    plays as it did, whatever gestures above it do); from the pose of the gesture it takes over from at its
    start frame, over its blend in; the spine, neck and head as the animation plays them without the turns
    other gestures add. values: {bone: (N, C) rotation channel values underneath}."""
    animated, resting, count = rig.animated, {}, len(frames)
    pose_bones, previous = plan.obj.pose.bones, plan.request.previous
    if previous is not None and previous.still:
        animated, moved = gestures.animator_bones(plan.obj)
        resting = {bone: armature_io.rotation_basis(pose_bones[bone], kept)
                   for bone, kept in previous.record["under"].items()
                   if bone in rig.skeleton.index and bone not in moved}
    torso = {rig.roles[role]: values[rig.roles[role]] for role in gesture.TORSO if role in rig.roles}
    own = previous.torso.track if previous is not None and previous.torso is not None else None
    animation, above = gestures.torso_layers(plan.obj, torso, frames, own)
    bare = {}
    for bone, kept in animation.items():
        bare[bone] = np.tile(np.eye(4), (count, 1, 1))
        bare[bone][:, :3, :3] = pose_underneath.rotation_matrices(pose_bones[bone].rotation_mode, kept)
    held = gesture.blend_ramp(count) + 1 if plan.request.taken is not None else 0
    return gesture.RigState(rig.name, rig.skeleton, rig.roles, rig.family, rig.under, animated, rig.under_pose,
                            still=plan.request.still, held=held, resting=resting, bare=bare, above=above)


def _keys(plan, bones, keyed, main_blend_type, below, below_values):
    """({MAIN: keys, TORSO: keys} (key_layers.key_action's), the worst deviation of editable keys in degrees) of
    the bones in their own rotation modes: the spine, neck and head on the Combine torso layer, the others on the
    main one, of `main_blend_type`. A torso bone in axis-angle goes on the main layer: the NLA adds axis-angle
    channels over nothing below as over zeros, not over the mode's rest (0, 0, 1, 0), so a Combine key of it would
    not play as planned."""
    settings, roles, pose_bones = plan.settings, plan.armature.roles, plan.obj.pose.bones
    torso = {roles[role] for role in gesture.TORSO
             if role in roles and pose_bones[roles[role]].rotation_mode != "AXIS_ANGLE"}
    keys, worst = {MAIN: {}, TORSO: {}}, 0.0
    for column, bone in enumerate(bones):
        layer = TORSO if bone in torso else MAIN
        blend_type = "COMBINE" if layer == TORSO else main_blend_type
        mode = pose_bones[bone].rotation_mode
        values = channels.rotation_keys(mode, keyed[:, column], below[:, column], below_values[bone], blend_type)
        kept = None
        if settings.editable_keys:
            added = below_values[bone] if blend_type == "COMBINE" and mode != "QUATERNION" else None
            kept, deviation = key_reduction.reduce_keys(mode, values, settings.key_tolerance, offset=added)
            worst = max(worst, deviation)
        keys[layer][bone] = (mode, values, kept)
    return keys, worst


def generate(context, settings, progress=lambda step: None, mute_constraints=False):
    """Bake a gesture onto the active armature and every other selected one; returns a summary, one line
    per armature. Each armature uses its own settings where it has them switched on (Object.rlanimate),
    else the shared `settings` (one target for all), and bakes again the gesture selected in the panel's list
    (Object.rlanimate.gesture), if any.

    Every check, for every armature, runs before the first write, so an RLAnimateError leaves the file
    as it was (the scene frame included). Constraints that would override the gesture are refused, or
    muted over its frames with mute_constraints (blender/constraints.py). After the writes each rig is
    played and its deformed hand measured (blender/bake_check.py): a bake that does not play is undone,
    every armature's, and refused.
    """
    armatures = selected_armatures(context, settings)
    requests = [(obj, properties.settings_for(obj, settings), gestures.selected(obj)) for obj in armatures]
    return bake(context, requests, progress, mute_constraints)


#: Follow Target's previews (`bake`): the gesture baked again over the rig as read at the drag's start, or its
#: aim alone.
GESTURE, AIM = "gesture", "aim"


def bake(context, requests, progress=lambda step: None, mute_constraints=False, cascade=True, preview=""):
    """`generate` for [(armature, its settings, the name of the gesture to bake again or "")]; returns the
    summary. With cascade, the gestures that depend on those it changed are baked again after. Frames it plays
    through Blender evaluate the armatures, not the meshes they deform (playback.armature_only); the scene is
    evaluated whole once at the end.

    preview (Follow Target while a target is dragged): GESTURE bakes each gesture over the rig as the drag's first
    re-bake read it (`_read_once`), AIM the gesture the drag baked last aimed at the target where it is now (the
    agent not run again); either checks the bake, neither bakes its dependants again. A bake that is not a
    preview forgets what previews reuse."""
    if not preview:
        forget_reads()
    _baking.append(True)
    try:
        return _bake(context, requests, progress, mute_constraints, cascade, preview)
    finally:
        _baking.pop()


#: One entry per bake under way (a bake bakes dependants again inside it).
_baking: list = []


def baking():
    """Whether a bake is under way (the frames it plays fire depsgraph handlers: Follow Target waits)."""
    return bool(_baking)


def _bake(context, requests, progress, mute_constraints, cascade, preview):
    plans = [_plan(obj, own, selected, mute_constraints, preview) for obj, own, selected in requests]
    agent = preferences.selected_agent(context)
    for plan in plans:
        gesture.check_length(int(plan.settings.frame_count))
        check_frames(int(plan.settings.start_frame), int(plan.settings.frame_count))
        _check_request(plan.settings, agent)
    progress(1)
    # A preview over a rig read before plays only the bake check's frames: the meshes then cost less than
    # switching their modifiers off and on.
    read = preview and all(_read_key(plan, plan.frames[0] + np.arange(plan.frames[1] - plan.frames[0] + 1))
                           in _reads for plan in plans)
    with playback.armature_only(context.view_layer, [] if read else _evaluated(plans), not read) as switched:
        lines = _bake_plans(context, plans, agent, progress, cascade)
    if switched:
        context.view_layer.update()
    return "\n".join(lines)


def _evaluated(plans):
    """The objects a bake of the plans reads as Blender evaluates them: the armatures, the targets of the plans
    and of the armatures' gestures (baked again after)."""
    found = {plan.obj for plan in plans} | {plan.settings.target for plan in plans}
    for plan in plans:
        found |= {g.record["settings"].get("target") for g in gestures.placed_gestures(plan.obj)}
    return [obj for obj in found if isinstance(obj, bpy.types.Object)]


def _bake_plans(context, plans, agent, progress, cascade):
    """Compute, write and verify the checked plans, then bake their dependants again; returns the summary lines."""
    # Backups of the gestures it changes (rewritten in place, trimmed), made before BakeUndo records the file.
    trimmed = [key_layers.Backup(plan.request.taken) for plan in plans if plan.request.taken is not None]
    rewritten = [key_layers.Backup(plan.request.previous) for plan in plans if plan.request.previous is not None]
    made = []
    try:
        for plan in plans:
            start, count = plan.frames[0], int(plan.settings.frame_count)
            if plan.request.taken is not None:  # its pose at the handover is where this one starts
                key_layers.trim(plan.request.taken, start, gesture.blend_ramp(count))
            # The gesture baked again set aside while the rig is read (unless a preview reads it no more), and put
            # back as it stood should the bake be refused.
            previous = [plan.request.previous] if plan.request.previous is not None else []
            reread = not (plan.request.preview and _read_key(plan, start + np.arange(count)) in _reads)
            with gestures.detached(previous, context.view_layer) if reread else contextlib.nullcontext():
                made.append(_compute(context, plan, agent, start + np.arange(count)))
    except BaseException:
        for backup in trimmed:
            backup.restore()
        for backup in rewritten:
            backup.discard()
        raise
    progress(3)
    written = _write_and_verify(context, made, agent, trimmed + rewritten)
    progress(4)
    if cascade and not any(plan.request.preview for plan in plans):
        return [line + _cascade(context, plan, action) for (line, action), plan in zip(written, plans, strict=True)]
    return [line for line, _ in written]


def _write_and_verify(context, plans, agent, backups):
    """Write every plan, then play each and verify it (blender/bake_check.py): a bake that does not play is
    undone, every plan's, the gestures it changed put back. Returns (summary line, action written) per plan."""
    undo = [bake_check.BakeUndo(plan.obj, plan.armature.overriding, rigify.switches(plan.obj, plan.gesture.properties))
            for plan in plans]
    scene = context.scene
    original_frame = scene.frame_current
    written = [_write(plan, agent, scene) for plan in plans]
    try:
        # One BLAS thread, as in _compute: over an animated rig the check inverts a 4 x 4 matrix per bone and
        # frame, which took 3.5 times the CPU on threaded OpenBLAS.
        with blas_threads.single_blas_thread():
            for plan in plans:
                bake_check.verify(scene, plan)
    except RLAnimateError:
        for record in reversed(undo):
            record.restore()
        for backup in backups:
            backup.restore()
        raise
    finally:
        scene.frame_set(original_frame)
    for backup in backups:
        backup.discard()
    return written


#: The role prefix of the arm a gesture on each arm does not gesture with.
_OTHER = {"LEFT": "Right", "RIGHT": "Left"}


def _write(plan, agent, scene):
    """Write one armature's planned gesture; returns (its summary line, the action written)."""
    settings, obj, request, made = plan.settings, plan.obj, plan.request, plan.gesture
    (start, end), count = plan.frames, int(settings.frame_count)
    label = f"RLAnimate {behaviours.title(settings.behaviour)} {settings.arm.title()}"
    played = (min(scene.frame_start, start), max(scene.frame_end, end))
    if request.previous is not None:  # its constraints' fade undone first, so the new one applies once
        constraints.unmute(obj, gestures.influence_before(request.previous))
        gesture_id = int(request.previous.record.get("id", gestures.next_id(obj)))
        memories = key_layers.rewrite(request.previous, label, start, made.keys, made.blend_type, made.properties,
                                      gesture_id, in_place=bool(request.preview))
        action = request.previous.action
    else:
        gesture_id = gestures.next_id(obj)
        action, memories = key_layers.place(obj, label, start, made.keys, made.blend_type, played, made.properties,
                                            request.still, gesture_id)
    influence_before = constraints.mute(obj, plan.armature.overriding, start, end, made.hold)
    kind = agent.kind(settings.behaviour)
    other = {bone for role, bone in plan.armature.roles.items()
             if role.startswith(_OTHER[settings.arm]) and "Eye" not in role}
    gestures.record(action, {
        "id": gesture_id, "behaviour": settings.behaviour, "kind": kind, "arm": settings.arm, "start": start,
        "end": end, "settings": gestures.snapshot(settings), "under": made.under, "aimed_at": made.targets,
        "influence_before": influence_before, "animated": not request.still},
        memories, {(path, i) for path, i, *_ in memories[MAIN].curves if gestures.bone_of(path) in other})
    placed = gestures.find(obj, action.name)
    if request.taking is not None:  # plays until the later gesture on its arm takes over
        key_layers.trim(placed, request.taking.start, gesture.blend_ramp(request.taking.end - request.taking.start + 1))
    gestures.renamed(obj, request.before.id if request.before else "", action.name)
    return _summary(plan, agent, scene, placed, count), action


def _summary(plan, agent, scene, placed, count):
    """The report line of a written plan: what was baked where, and how it composes with the others."""
    settings, made = plan.settings, plan.gesture
    start, end = plan.frames
    label = f"{behaviours.title(settings.behaviour)} {settings.arm.title()}"
    note = _length_notes(plan, agent, scene, count) + _composing_notes(plan, placed)
    if made.from_ik:  # an animated switch already at FK is keyed at FK, and nothing is said
        note += f" (the {settings.arm.lower()} arm switched from IK to FK over its frames)"
    if plan.armature.overriding:
        held = (", held muted beyond them: they hold the rig at rest, so it stands as a still rig does"
                if made.hold else "")
        note += f" (muted {constraints.describe(plan.armature.overriding)} over its frames{held})"
    layer = "" if plan.request.still else f", {made.blend_type.title()} layer over its animation"
    editable = ""
    if settings.editable_keys:
        keys = sum(len(kept) * values.shape[1] for layer_keys in made.keys.values()
                   for _, values, kept in layer_keys.values())
        editable = f"; editable: {keys} Bezier keys, worst deviation {made.worst:.2f} deg"
    if end > scene.frame_end:
        note += (f" ({gesture.LENGTH_WARNING} frames {start}-{end} run past the scene's end, frame "
                 f"{scene.frame_end}: click 'Extend Scene End' in the RLAnimate panel to play them)")
    return (f"Baked {label} on {plan.obj.name!r} ({plan.armature.family} bones): {len(made.bones)} bones, frames "
            f"{start}-{end}, action {placed.action.name!r}{layer}{note}{editable}")


def _length_notes(plan, agent, scene, count):
    """Notes on the gesture's length and aim: time-scaled, rushed, the agent's own aim."""
    settings = plan.settings
    span = frame_rate.agent_frames(count, properties.scene_fps(scene))
    steps = gesture.rollout_length(span, agent.average_frames[settings.behaviour], agent.kind(settings.behaviour))
    note = f" (time-scaled from the agent's {steps}-frame gesture)" if steps != span else ""
    note += gesture.length_warning(count, agent.average_frames[settings.behaviour])
    if agent.space.behaviour(settings.behaviour).aims and not settings.exact_aim:
        note += " (the agent's own aim: Exact Aim is off)"
    return note


def _composing_notes(plan, placed):
    """Notes on how the gesture composes with the armature's others: baked again, taking over, trimmed, its
    spine and head turns added to others'."""
    request = plan.request
    note = " (replaced the previous gesture)" if request.previous is not None else ""
    start, end = plan.frames
    if request.taken is not None:
        note += f" (takes over from {request.taken.name!r} at frame {start}, which plays until there)"
    if request.taking is not None:
        note += f" (plays until frame {request.taking.start}, where {request.taking.id!r} takes over)"
    span = placed.span
    sharing = [g for g in gestures.placed_gestures(plan.obj) if g.action != placed.action and g.span.overlaps(span)
               and not (request.taken is not None and g.action == request.taken.action)]
    for other in sharing:
        first, last = max(start, other.span.start), min(end, other.span.end)
        note += (f" (its spine, neck and head turns add to those of {other.name!r} over frames {first}-{last}, "
                 "so both play)")
    return note


def _cascade(context, plan, action):
    """Bake again, from their records, the armature's gestures that depend on the one the plan changed (its
    `action` written), but those edited by hand (core.composition.dependants); returns a note on what was and
    was not."""
    obj = plan.obj
    placed = gestures.placed_gestures(obj)
    now = next(g for g in placed if g.action == action)
    return rebake(context, obj, composition.dependants([g.span for g in placed], plan.request.before, now.span))


def rebake(context, obj, spans):
    """Bake the armature's gestures of `spans` again from their records, bottom first, each with the constraint
    mutes it was baked with; a gesture edited by hand, or whose bake is refused now, is left as it is. Returns
    a note saying which were baked again and which not, and why."""
    again, left = [], []
    for span in spans:
        placed = gestures.find(obj, span.id)
        if placed is None:
            continue
        if gestures.edited(placed):
            left.append(f"{span.id!r} was edited by hand, so it keeps its keys: select it and Generate to "
                        "bake it over the new pose")
            continue
        try:
            bake(context, [(obj, recorded_settings(placed.record), span.id)],
                 mute_constraints=bool(placed.record.get("influence_before")), cascade=False)
            again.append(repr(span.id))
        except RLAnimateError as error:
            left.append(f"{span.id!r} could not be baked again over it: {error}")
    note = f" (baked again over the new pose: {', '.join(again)})" if again else ""
    return note + "".join(f" ({text})" for text in left)


def recorded_settings(record):
    """A gesture's recorded settings as Generate reads them (no target: None)."""
    return types.SimpleNamespace(**{"target": None, "replace_edited_keys": False,
                                    **record["settings"].to_dict()})


class RLANIMATE_OT_generate_gesture(bpy.types.Operator):
    """Bake the chosen behaviour's gesture onto the selected armatures with the RLAnimate agent (or bake the
    gesture selected in the panel's list again)"""
    bl_idname = "rlanimate.generate_gesture"
    bl_label = "Generate Gesture"
    bl_options = {"REGISTER", "UNDO"}

    mute_constraints: bpy.props.BoolProperty(
        name="Mute Arm Constraints", default=False, options={"SKIP_SAVE"},
        description="Mute constraints that would override the gesture (IK, Copy Rotation...) over the "
                    "gesture's frames only, with a driver on their influence")

    def execute(self, context):
        window_manager = context.window_manager
        window_manager.progress_begin(0, 4)
        try:
            summary = generate(context, context.scene.rlanimate, window_manager.progress_update,
                               mute_constraints=self.mute_constraints)
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            window_manager.progress_end()
        self.report({"WARNING"} if gesture.LENGTH_WARNING in summary else {"INFO"}, summary)
        return {"FINISHED"}
