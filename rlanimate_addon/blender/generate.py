"""Generate Gesture: run the agent for the scene's settings and bake the result onto the selected armatures."""
import bpy
import numpy as np

from ..core import behaviours, blas_threads, channels, frame_rate, gesture, key_reduction, rig_roles, rig_scale
from ..core import rigify as rig_rigify
from ..core.errors import RLAnimateError
from . import action_adapter, armature_io, bake_check, constraints, gestures, preferences, properties, rigify


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
    """The armatures to bake onto: the active object, which must be one, then every other selected
    armature (the Point target excluded)."""
    active = context.active_object
    if active is None or active.type != "ARMATURE":
        raise RLAnimateError("The active object is not an armature: select the character's armature.")
    return [active] + [o for o in context.selected_objects
                       if o.type == "ARMATURE" and o is not active and o is not settings.target]


class _Plan:
    """One armature's checked settings, and then its gesture, ready to write."""

    def __init__(self, obj, family, roles, overriding, ik_share=None):
        self.obj, self.family, self.roles, self.overriding = obj, family, roles, overriding
        self.ik_share = ik_share  # a Rigify arm in IK: its IK_FK value, switched to FK over the gesture
        self.properties = None
        self.rig = self.bones = self.keyed = self.keys = self.blend_type = self.settings = None
        self.target, self.target_bone, self.targets = None, "", None  # Point's target and where it was read
        self.previous = None  # the gesture it replaces (blender/gestures.py)
        self.under = {}  # {bone: channel values} of keyed bones that stand still underneath
        self.worst = 0.0
        self.hold = False  # the constraints it mutes stay muted beyond its frames (constraints.follow_rest)


def _check(obj, settings, start, end, mute_constraints):
    """The armature's _Plan; RLAnimateError when it cannot take the gesture."""
    family, roles = armature_io.rig_roles_of(obj, settings.bone_map_file)
    rig_roles.check_roles(obj.name, roles, settings.arm, family)
    ik_share = rigify.ik_share(obj, settings.arm) if family == rig_roles.RIGIFY.name else None
    check_keepable(obj)
    check_nla(obj)
    check_inherited_rotation(obj, roles)
    armature_io.check_hips(obj, roles)
    rig_scale.check_nonzero_scale(obj.name, obj.matrix_world,
                                  _scales(obj, constraints.driven_bones(roles, settings.behaviour, settings.arm)))
    # Eyes the rig already aims with constraints (a Damped Track to an eye target) stay the rig's.
    roles = {role: bone for role, bone in roles.items()
             if not (role.endswith("Eye") and len(obj.pose.bones[bone].constraints))}
    driven = constraints.driven_bones(roles, settings.behaviour, settings.arm)
    constraints.check_drivers(obj, driven)
    overriding = constraints.against_gesture(obj, driven)
    constraints.check(obj, overriding, start, end, mute_constraints)
    return _Plan(obj, family, roles, overriding, ik_share)


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


def _compute(context, plan, settings, agent, frames):
    """Fill in the plan's gesture and keys (nothing written), on one BLAS thread: every product here is
    small, and on a machine with busy cores BLAS threads only wait (core/blas_threads.py)."""
    with blas_threads.single_blas_thread():
        obj, scene = plan.obj, context.scene
        original_frame = scene.frame_current
        targeted = agent.kind(settings.behaviour) == behaviours.TARGET
        target = settings.target if targeted else None
        bone = target_bone(settings) if target else ""
        try:
            # Read with the constraints it mutes off: the pose the gesture plays over, which Exact Aim solves on.
            with constraints.muted(context.view_layer, plan.overriding):
                rig, below_values, targets = armature_io.sample_rig(context, obj, plan.roles, plan.family, frames,
                                                                    target, bone)
            if plan.previous is not None and not plan.previous.record.get("animated", True):
                # It replaces a gesture made on a still rig: with nothing else moving these frames (other
                # gestures elsewhere make the rig animated), it plays as that first one did.
                rig, below_values = rig.standing_still(below_values) or (rig, below_values)
            if plan.ik_share is not None:  # the FK controls start where the arm stands in IK
                played, switch = rigify.played_arm(context, obj, settings.arm, frames, rig.animated)
                rig = rig_rigify.snap_fk(rig, rig_rigify.fk_controls(settings.arm), played)
        finally:
            if scene.frame_current != original_frame:
                scene.frame_set(original_frame)
        request = gesture.GestureRequest(settings.behaviour, settings.arm, len(frames),
                                         targets=targets if targeted else None,
                                         exaggeration=settings.exaggeration, seed=settings.seed or None,
                                         tempo=settings.tempo or None, exact_aim=settings.exact_aim,
                                         fps=properties.scene_fps(scene))
        plan.bones, keyed, below = gesture.gesture_rotations(agent, request, rig)
        plan.keyed = keyed
        if target is not None:
            plan.target, plan.target_bone, plan.targets = target, bone, targets
        plan.rig, plan.blend_type = rig, settings.blend_type if rig.animated else "REPLACE"
        # A still rig held at rest by its constraints stands as any still rig does: they stay muted.
        plan.hold = bool(plan.overriding) and not rig.animated and constraints.follow_rest(obj, plan.overriding)
        if plan.ik_share is not None:
            plan.properties = rigify.switch_keys(obj, settings.arm, switch, plan.blend_type, rig.animated)
        plan.under = {
            bone: below_values[bone][0] for bone in plan.bones if not np.ptp(below_values[bone], axis=0).any()
        }
        plan.keys = {}
        for column, bone in enumerate(plan.bones):
            mode = obj.pose.bones[bone].rotation_mode
            values = channels.rotation_keys(mode, keyed[:, column], below[:, column], below_values[bone],
                                            plan.blend_type)
            kept = None
            if settings.editable_keys:
                added = below_values[bone] if plan.blend_type == "COMBINE" and mode != "QUATERNION" else None
                kept, deviation = key_reduction.reduce_keys(mode, values, settings.key_tolerance, offset=added)
                plan.worst = max(plan.worst, deviation)
            plan.keys[bone] = (mode, values, kept)


def generate(context, settings, progress=lambda step: None, mute_constraints=False):
    """Bake a gesture onto the active armature and every other selected one; returns a summary, one line
    per armature. Each armature uses its own settings where it has them switched on (Object.rlanimate),
    else the shared `settings` (one target for all).

    Every check, for every armature, runs before the first write, so an RLAnimateError leaves the file
    as it was (the scene frame included). Constraints that would override the gesture are refused, or
    muted over its frames with mute_constraints (blender/constraints.py). After the writes each rig is
    played and its deformed hand measured (blender/bake_check.py): a bake that does not play is undone,
    every armature's, and refused. A gesture on the same arm over overlapping frames is
    replaced in place unless Keep Previous is on (blender/gestures.py).
    """
    armatures = selected_armatures(context, settings)
    return bake(context, [(obj, properties.settings_for(obj, settings)) for obj in armatures], progress,
                mute_constraints)


def bake(context, requests, progress=lambda step: None, mute_constraints=False):
    """`generate` for [(armature, its settings)]; returns the summary."""
    plans = []
    for obj, own in requests:
        start = int(own.start_frame)
        end = start + int(own.frame_count) - 1
        plan = _check(obj, own, start, end, mute_constraints)
        plan.settings = own
        plan.previous = None if own.keep_previous else gestures.overlapping(obj, own.arm, start, end)
        plans.append(plan)
    agent = preferences.selected_agent(context)
    for plan in plans:
        gesture.check_length(int(plan.settings.frame_count))
        check_frames(int(plan.settings.start_frame), int(plan.settings.frame_count))
        _check_request(plan.settings, agent)
    progress(1)
    for plan in plans:
        start, count = int(plan.settings.start_frame), int(plan.settings.frame_count)
        with gestures.detached(plan.previous, context.view_layer):
            _compute(context, plan, plan.settings, agent, start + np.arange(count))
    progress(3)
    replaced = [gestures.Backup(plan.previous) for plan in plans if plan.previous is not None]
    undo = [bake_check.BakeUndo(plan.obj, plan.overriding, rigify.switches(plan.obj, plan.properties))
            for plan in plans]
    scene = context.scene
    original_frame = scene.frame_current
    lines = [_write(plan, agent, scene) for plan in plans]
    try:
        # One BLAS thread, as in _compute: over an animated rig the check inverts a 4 x 4 matrix per bone and
        # frame, which took 3.5 times the CPU on threaded OpenBLAS.
        with blas_threads.single_blas_thread():
            for plan in plans:
                bake_check.verify(scene, plan)
    except RLAnimateError:
        for record in reversed(undo):
            record.restore()
        for backup in replaced:
            backup.restore()
        raise
    finally:
        scene.frame_set(original_frame)
    for backup in replaced:
        backup.discard()
    progress(4)
    return "\n".join(lines)


def _write(plan, agent, scene):
    """Write one armature's planned gesture; returns its summary line."""
    settings = plan.settings
    start, count = int(settings.start_frame), int(settings.frame_count)
    end = start + count - 1
    label = f"{behaviours.title(settings.behaviour)} {settings.arm.title()}"
    note = ""
    span = frame_rate.agent_frames(count, properties.scene_fps(scene))
    kind = agent.kind(settings.behaviour)
    steps = gesture.rollout_length(span, agent.average_frames[settings.behaviour], kind)
    if steps != span:
        note += f" (time-scaled from the agent's {steps}-frame gesture)"
    note += gesture.length_warning(count, agent.average_frames[settings.behaviour])
    if settings.behaviour == behaviours.POINT and not settings.exact_aim:
        note += " (the agent's own aim: Exact Aim is off)"
    digest = action_adapter.KeyDigest()
    if plan.previous is not None:  # its constraints' fade undone first, so the new one applies once
        constraints.unmute(plan.obj, gestures.influence_before(plan.previous))
        action = gestures.replace(plan.previous, f"RLAnimate {label}", start, plan.keys, plan.blend_type, digest,
                                  plan.properties)
        note += " (replaced the previous gesture)"
    else:
        action = armature_io.write_gesture(plan.obj, f"RLAnimate {label}", start, plan.keys, plan.blend_type,
                                           (min(scene.frame_start, start), max(scene.frame_end, end)), digest,
                                           plan.properties)
    if plan.ik_share is not None:
        note += f" (the {settings.arm.lower()} arm switched from IK to FK over its frames)"
    influence_before = constraints.mute(plan.obj, plan.overriding, start, end, plan.hold)
    gestures.record(action, gestures.snapshot(settings), kind, start, end, plan.under, plan.targets,
                    digest.hexdigest(), influence_before, plan.rig.animated)
    muted = ""
    if plan.overriding:
        held = (", held muted beyond them: they hold the rig at rest, so it stands as a still rig does"
                if plan.hold else "")
        muted = f" (muted {constraints.describe(plan.overriding)} over its frames{held})"
    layer = f", {plan.blend_type.title()} layer over its animation" if plan.rig.animated else ""
    editable = ""
    if settings.editable_keys:
        keys = sum(len(kept) * values.shape[1] for _, values, kept in plan.keys.values())
        editable = f"; editable: {keys} Bezier keys, worst deviation {plan.worst:.2f} deg"
    return (f"Baked {label} on {plan.obj.name!r} ({plan.family} bones): {len(plan.bones)} bones, frames "
            f"{start}-{end}, action {action.name!r}{layer}{muted}{note}{editable}")


class RLANIMATE_OT_generate_gesture(bpy.types.Operator):
    """Bake the chosen behaviour's gesture onto the selected armatures with the RLAnimate agent"""
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

