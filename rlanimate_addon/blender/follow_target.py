"""Follow Target: while Scene.rlanimate.follow_target is on, moving the target of an armature's last
gesture of a target behaviour (Point) re-bakes that gesture, so a dragged empty has the arm following it.

A depsgraph_update_post handler (persistent, so it outlives a file load) looks, after each update
that touched an object, whether the target of an armature's last target gesture (blender/gestures.py)
now sits elsewhere than the gesture aimed at on the current frame, and re-bakes the gesture from its
recorded settings, replacing it in place. Re-bakes are throttled: one runs at once, later moves
within THROTTLE seconds wait for a timer that re-bakes once for the last position. A gesture whose
keys were edited by hand since it was baked is never re-baked: following it stops, with a note on
the gesture that the panel shows, until Generate bakes it again. A gesture baked with Generate, Muting
Constraints is re-baked muting them again.
"""
import time

import bpy
import numpy as np

from ..core.errors import RLAnimateError
from . import armature_io, generate, gestures

#: Seconds between two re-bakes while a target is dragged.
THROTTLE = 1.0 / 30.0
#: A target that moved less than this (in the armature's units) has not moved.
MOVED = 1e-6

_state = {"busy": False, "last": -np.inf, "pending": False}


def _moved(obj, gesture, scene):
    """Whether the gesture's target sits elsewhere than it aimed at on the current frame."""
    record = gesture.record
    settings = generate.recorded_settings(record)
    target = settings.target
    if target is None or len(record["aimed_at"]) == 0:
        return False  # the 3D cursor is not followed
    aimed = np.reshape(record["aimed_at"], (-1, 3))  # (N, 3)
    offset = scene.frame_current - record["start"]
    if not 0 <= offset < len(aimed) and armature_io.may_move(target):
        return False  # an animated target is compared over the gesture's own frames only
    now = armature_io.target_point(obj, target, generate.target_bone(settings), scene)
    return bool(np.abs(now - aimed[int(np.clip(offset, 0, len(aimed) - 1))]).max() > MOVED)


def _stop(gesture, why):
    gesture.record["note"] = f"Follow Target stopped for {gesture.action.name!r}: {why}"


def follow(scene, moved=None):
    """Re-bake every armature's last target gesture whose target moved (`moved`: the objects an update
    touched, None for any); returns the armatures re-baked."""
    rebaked = []
    for obj in [o for o in scene.objects if o.type == "ARMATURE"]:
        gesture = gestures.last_targeted(obj)
        if gesture is None or gesture.record["note"]:
            continue
        target = generate.recorded_settings(gesture.record).target
        if moved is not None and obj not in moved and target not in moved:
            continue
        if not _moved(obj, gesture, scene):
            continue
        if gestures.edited(gesture):
            _stop(gesture, "its keys were edited by hand since it was baked, and a re-bake would lose the edits. "
                           "Generate it again to follow its target")
            continue
        try:
            # A gesture baked muting constraints had the animator's consent to mute them: it still has.
            generate.bake(bpy.context, [(obj, generate.recorded_settings(gesture.record), gesture.name)],
                          mute_constraints=bool(gesture.record.get("influence_before")))
        except RLAnimateError as error:
            _stop(gesture, str(error))
            continue
        rebaked.append(obj)
    return rebaked


def _follow_later():
    _state["pending"] = False
    _on_update(bpy.context.scene, None)


@bpy.app.handlers.persistent
def _on_update(scene, depsgraph):
    if _state["busy"] or scene is None or not scene.rlanimate.follow_target:
        return
    moved = None
    if depsgraph is not None:
        moved = {update.id.original for update in depsgraph.updates if isinstance(update.id, bpy.types.Object)}
        if not moved:
            return
    now = time.monotonic()
    if now - _state["last"] < THROTTLE:
        if not _state["pending"]:
            _state["pending"] = True
            bpy.app.timers.register(_follow_later, first_interval=THROTTLE)
        return
    _state["busy"] = True
    try:
        if follow(scene, moved):
            _state["last"] = time.monotonic()
    finally:
        _state["busy"] = False


def note(obj):
    """Why Follow Target stopped for the armature's last target gesture, or ""."""
    gesture = None if obj is None or obj.type != "ARMATURE" else gestures.last_targeted(obj)
    return "" if gesture is None else gesture.record["note"]


def register():
    if _on_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(_on_update)


def unregister():
    if _on_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_on_update)
    if bpy.app.timers.is_registered(_follow_later):
        bpy.app.timers.unregister(_follow_later)
    _state.update(busy=False, pending=False)
