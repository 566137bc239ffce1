"""Generate Gesture: run the agent for the scene's settings and bake the result onto the active armature."""
import bpy
import numpy as np

from ..core import channels, gesture, rig_roles
from ..core.errors import RLAnimateError
from . import action_adapter, armature_io, preferences


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


def generate(context, settings, progress=lambda step: None):
    """Bake the gesture the settings describe onto the active armature; returns a one-line summary.

    Every check runs before the first write, so an RLAnimateError leaves the file as it was (the scene
    frame included).
    """
    obj = context.active_object
    family, roles = armature_io.rig_roles_of(obj, settings.bone_map_file)
    rig_roles.check_roles(obj.name, roles, settings.arm, family)
    agent = preferences.selected_agent(context)
    frame_count, start = int(settings.frame_count), int(settings.start_frame)
    if frame_count < 2:
        raise RLAnimateError(f"The gesture is {frame_count} frames long: set a length of at least 2 frames.")
    _check_target(settings)
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
    progress(4)
    note = ""
    shortest, longest = gesture.supported_length_range(agent.average_frames[settings.behaviour])
    if not shortest <= frame_count <= longest:
        note = f" (time-scaled: the agent's range is {shortest}-{longest} frames)"
    if settings.behaviour == "POINT" and not settings.exact_aim:
        note += " (the agent's own aim: Exact Aim is off)"
    layer = f", {blend_type.title()} layer over its animation" if rig.animated else ""
    return (f"Baked {label} on {obj.name!r} ({family} bones): {len(bones)} bones, frames {start}-"
            f"{start + frame_count - 1}, action {action.name!r}{layer}{note}")


class RLANIMATE_OT_generate_gesture(bpy.types.Operator):
    """Bake a pointing or waving gesture onto the active armature with the RLAnimate agent"""
    bl_idname = "rlanimate.generate_gesture"
    bl_label = "Generate Gesture"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        window_manager = context.window_manager
        window_manager.progress_begin(0, 4)
        try:
            summary = generate(context, context.scene.rlanimate, window_manager.progress_update)
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            window_manager.progress_end()
        self.report({"INFO"}, summary)
        return {"FINISHED"}

