"""Generate Gesture: run the agent for the scene's settings and bake the result onto the active armature."""
import bpy
import numpy as np

from ..core import channels, gesture, rig_roles
from ..core.errors import RLAnimateError
from . import action_adapter, armature_io, constraints, preferences


def _check_target(settings):
    """RLAnimateError when Point has no target, or a target bone its target armature lacks."""
    if settings.behaviour != "POINT":
        return
    if settings.target is None and not settings.use_cursor:
        raise RLAnimateError("Point needs a target: pick a target object, or tick 'Use 3D Cursor'.")
    target, bone = settings.target, settings.target_bone
    if target is not None and bone and (target.type != "ARMATURE" or bone not in target.pose.bones):
        raise RLAnimateError(f"The target {target.name!r} has no bone {bone!r}: pick one of its bones, "
                             "or clear Target Bone to point at the object itself.")


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


def check_frames(start, frame_count):
    """RLAnimateError when the gesture's frames leave Blender's frame range."""
    low, high = _FRAMES.hard_min, _FRAMES.hard_max
    if start < low or start + frame_count - 1 > high:
        raise RLAnimateError(f"Frames {start}-{start + frame_count - 1} leave Blender's frame range "
                             f"({low} to {high}), where keys cannot play: set a start frame from {low} to "
                             f"{high - frame_count + 1}.")


def generate(context, settings, progress=lambda step: None, mute_constraints=False):
    """Bake the gesture the settings describe onto the active armature; returns a one-line summary.

    Every check runs before the first write, so an RLAnimateError leaves the file as it was (the scene
    frame included). Constraints that would override the gesture are refused, or muted over its frames
    with mute_constraints (blender/constraints.py).
    """
    obj = context.active_object
    family, roles = armature_io.rig_roles_of(obj, settings.bone_map_file)
    rig_roles.check_roles(obj.name, roles, settings.arm, family)
    check_keepable(obj)
    agent = preferences.selected_agent(context)
    frame_count, start = int(settings.frame_count), int(settings.start_frame)
    gesture.check_length(frame_count)
    check_frames(start, frame_count)
    end = start + frame_count - 1
    _check_target(settings)
    overriding = constraints.overriding(obj, constraints.driven_bones(roles, settings.behaviour, settings.arm))
    constraints.check(obj, overriding, start, end, mute_constraints)
    progress(1)

    scene = context.scene
    original_frame = scene.frame_current
    frames = start + np.arange(frame_count)
    target = settings.target if settings.behaviour == "POINT" else None
    try:
        rig, below_values, targets = armature_io.sample_rig(context, obj, roles, family, frames, target,
                                                            settings.target_bone if target else "")
    finally:
        if scene.frame_current != original_frame:
            scene.frame_set(original_frame)
    progress(2)

    request = gesture.GestureRequest(settings.behaviour, settings.arm, frame_count,
                                     targets=targets if settings.behaviour == "POINT" else None,
                                     exaggeration=settings.exaggeration, seed=settings.seed or None,
                                     exact_aim=settings.exact_aim)
    bones, keyed, below = gesture.gesture_rotations(agent, request, rig)
    blend_type = settings.blend_type if rig.animated else "REPLACE"
    keys = {}
    for column, bone in enumerate(bones):
        mode = obj.pose.bones[bone].rotation_mode
        keys[bone] = (mode, channels.rotation_keys(mode, keyed[:, column], below[:, column],
                                                   below_values[bone], blend_type))
    progress(3)

    label = f"{settings.behaviour.title()} {settings.arm.title()}"
    action = armature_io.write_gesture(obj, f"RLAnimate {label}", start, keys, blend_type)
    constraints.mute(obj, overriding, start, end)
    progress(4)
    note = f" (muted {constraints.describe(overriding)} over its frames)" if overriding else ""
    shortest, longest = gesture.supported_length_range(agent.average_frames[settings.behaviour])
    if not shortest <= frame_count <= longest:
        note += f" (time-scaled: the agent's range is {shortest}-{longest} frames)"
    if settings.behaviour == "POINT" and not settings.exact_aim:
        note += " (the agent's own aim: Exact Aim is off)"
    layer = f", {blend_type.title()} layer over its animation" if rig.animated else ""
    return (f"Baked {label} on {obj.name!r} ({family} bones): {len(bones)} bones, frames {start}-{end}, "
            f"action {action.name!r}{layer}{note}")


class RLANIMATE_OT_generate_gesture(bpy.types.Operator):
    """Bake a pointing or waving gesture onto the active armature with the RLAnimate agent"""
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
        self.report({"INFO"}, summary)
        return {"FINISHED"}

