"""Generate Gesture: run the agent for the scene's settings and bake the result onto the active armature."""
import bpy
import numpy as np

from ..core import gesture
from ..core.errors import RLAnimateError
from . import action_adapter, armature_io, preferences


def generate(context, settings, progress=lambda step: None):
    """Bake the gesture the settings describe onto the active armature; returns a one-line summary.

    Every check runs before the first write, so an RLAnimateError leaves the file as it was (the scene
    frame included).
    """
    obj = context.active_object
    names = armature_io.check_rig(obj)
    agent = preferences.selected_agent(context)
    frame_count, start = int(settings.frame_count), int(settings.start_frame)
    if frame_count < 2:
        raise RLAnimateError(f"The gesture is {frame_count} frames long: set a length of at least 2 frames.")
    if settings.behaviour == "POINT" and settings.target is None and not settings.use_cursor:
        raise RLAnimateError("Point needs a target: pick a target object, or tick 'Use 3D Cursor'.")
    progress(1)

    scene = context.scene
    original_frame = scene.frame_current
    frames = start + np.arange(frame_count)
    try:
        if action_adapter.is_animated(obj) and scene.frame_current != start:
            scene.frame_set(start)  # the pose to blend from is the one at the start frame
        rig = armature_io.read_rig_pose(obj, names)
        targets = None
        if settings.behaviour == "POINT":
            targets = armature_io.target_positions(scene, obj, settings.target, frames)
    finally:
        if scene.frame_current != original_frame:
            scene.frame_set(original_frame)
    progress(2)

    request = gesture.GestureRequest(settings.behaviour, settings.arm, frame_count, targets=targets,
                                     exaggeration=settings.exaggeration, seed=settings.seed or None,
                                     exact_aim=settings.exact_aim)
    canonical_names, quats = gesture.gesture_rotations(agent, request, rig)
    bones = [names[n] for n in canonical_names]
    armature_io.check_quaternion_bones(obj, bones)
    progress(3)

    label = f"{settings.behaviour.title()} {settings.arm.title()}"
    action = armature_io.write_gesture(obj, f"RLAnimate {label}", bones, start, quats)
    progress(4)
    note = ""
    shortest, longest = gesture.supported_length_range(agent.average_frames[settings.behaviour])
    if not shortest <= frame_count <= longest:
        note = f" (time-scaled: the agent's range is {shortest}-{longest} frames)"
    if settings.behaviour == "POINT" and not settings.exact_aim:
        note += " (the agent's own aim: Exact Aim is off)"
    return (f"Baked {label} on {obj.name!r}: {len(bones)} bones, frames {start}-{start + frame_count - 1}, "
            f"action {action.name!r}{note}")


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

