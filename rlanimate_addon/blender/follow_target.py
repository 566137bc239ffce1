"""Follow Target: while Scene.rlanimate.follow_target is on, moving the target of an armature's last gesture of a
target behaviour (Point) bakes that gesture again at the new position, so a dragged empty has the arm follow it.

A depsgraph_update_post handler (persistent, so it outlives a file load) looks, after each update that touched
an object, whether the target of an armature's last target gesture (blender/gestures.py) now sits elsewhere than
the gesture aimed at on the current frame. While the target is dragged, each move bakes the gesture again as a
preview (generate.bake's `preview`): the agent, the aim, the keys and the bake check for the new position, over
the pose underneath as the drag's first re-bake read it (reading it again frame by frame is what makes a re-bake
slow on a rig Blender must play, a Rigify rig), without baking again the gestures that depend on it. Where such
a preview takes longer than a KEEP_UP-th of a second, the rest of the drag previews the aim alone: Exact Aim and
the eyes solved for the new position over the gesture the drag baked last (the agent not run again). Once the
target has rested for REST seconds, the gesture is baked again in full, as Generate bakes it (the agent run, the
rig read again, its dependants baked again): the keys of the final position are exactly Generate's. Previews
start at most every THROTTLE seconds; a move that comes sooner waits for a timer.

A gesture whose keys were edited by hand since it was baked is never baked again, and one whose bake is refused
(its bake check, a check before it) is left as it was: following it stops, with a note on the gesture that the
panel shows and a report, until Generate bakes it again. A gesture baked with Generate, Muting Constraints is
baked again muting them again. The gesture keeps its actions' names, the animator's own included.
"""
import time

import bpy
import numpy as np

from ..core.errors import RLAnimateError
from . import armature_io, generate, gestures

#: Seconds from the start of one preview to the start of the next while a target is dragged.
THROTTLE = 1.0 / 30.0
#: Seconds a dragged target rests before its gesture is baked in full.
REST = 0.25
#: A target that moved less than this (in the armature's units) has not moved.
MOVED = 1e-6
#: Previews a second a drag keeps up with by baking the gesture again; below, it previews the aim alone.
KEEP_UP = 20.0

_state = {"last": -np.inf, "pending": False, "moved": -np.inf}
#: {(armature name, gesture name): the kind of its next preview} of the gestures previewed since they were last
#: baked in full.
_previewed: dict = {}
#: Reports waiting for the main loop (a depsgraph handler cannot report): `_flush_reports`.
reports: list = []


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


def _stop(obj, name, why):
    """Stop following the armature's gesture `name` (found again by name: a refused bake put its actions back as
    copies), with a note the panel shows and a report."""
    gesture = gestures.find(obj, name)
    message = f"Follow Target stopped for {name!r}: {why}"
    if gesture is not None:
        gesture.record["note"] = message
    _previewed.pop((obj.name, name), None)
    generate.forget_reads()
    reports.append(message)
    if not bpy.app.timers.is_registered(_flush_reports):
        bpy.app.timers.register(_flush_reports, first_interval=0.0)


def _flush_reports():
    """Report what stopped following (in the status bar and the Info log), from the main loop."""
    while reports:
        bpy.ops.rlanimate.follow_target_report(message=reports.pop(0))


def _rebake(obj, gesture, preview):
    """Bake the gesture again from its record; while its target is dragged (preview), as a preview of the
    gesture, or of its aim alone once a preview of the gesture took longer than a KEEP_UP-th of a second. False
    when it was edited by hand or its bake is refused: following it then stops."""
    name = gesture.name
    key = (obj.name, name)
    first = key not in _previewed
    if (first or not preview) and gestures.edited(gesture):
        _stop(obj, name, "its keys were edited by hand since it was baked, and a re-bake would lose the edits. "
                         "Generate it again to follow its target")
        return False
    if first:
        generate.forget_reads()  # a drag starts: the rig is read afresh
    settings = generate.recorded_settings(gesture.record)
    settings.replace_edited_keys = True  # checked above: a preview's own keys differ from its last full bake's
    kind = _previewed.get(key, generate.GESTURE) if preview else ""
    started = time.perf_counter()
    try:
        # A gesture baked muting constraints had the animator's consent to mute them: it still has.
        muting = bool(gesture.record.get("influence_before"))
        generate.bake(bpy.context, [(obj, settings, name)], mute_constraints=muting, preview=kind)
    except RLAnimateError as error:
        _stop(obj, name, str(error))
        return False
    if not preview:
        _previewed.pop(key, None)
    elif kind == generate.AIM or time.perf_counter() - started > 1.0 / KEEP_UP:
        _previewed[key] = generate.AIM  # too slow to keep up: the aim alone for the rest of the drag
    else:
        _previewed[key] = generate.GESTURE
    return True


def follow(scene, moved=None, preview=False):
    """Bake again every armature's last target gesture whose target moved (`moved`: the objects an update
    touched, None for any), in full or as a preview; returns the armatures baked again."""
    rebaked = []
    for obj in [o for o in scene.objects if o.type == "ARMATURE"]:
        gesture = gestures.last_targeted(obj)
        if gesture is None or gesture.record["note"]:
            continue
        target = generate.recorded_settings(gesture.record).target
        if moved is not None and obj not in moved and target not in moved:
            continue
        if _moved(obj, gesture, scene) and _rebake(obj, gesture, preview):
            rebaked.append(obj)
    return rebaked


def settle():
    """Bake in full each gesture previewed since its last full bake (its target rests now); returns the
    armatures baked again."""
    scene, rebaked = bpy.context.scene, []
    if generate.baking():
        return rebaked
    for obj_name, name in sorted(_previewed):
        obj = scene.objects.get(obj_name)
        gesture = None if obj is None else gestures.find(obj, name)
        _previewed.pop((obj_name, name), None)
        if gesture is not None and not gesture.record["note"] and _rebake(obj, gesture, preview=False):
            rebaked.append(obj)
    return rebaked


def _settle_later():
    """The timer that bakes in full once the target has rested REST seconds (called again until it has)."""
    waited = time.monotonic() - _state["moved"]
    if waited < REST:
        return REST - waited
    if generate.baking():
        return THROTTLE
    settle()
    return None


def _follow_later():
    _state["pending"] = False
    _on_update(bpy.context.scene, None)


def _wait(function, seconds):
    if not bpy.app.timers.is_registered(function):
        bpy.app.timers.register(function, first_interval=seconds)


@bpy.app.handlers.persistent
def _on_update(scene, depsgraph):
    if generate.baking() or scene is None or not scene.rlanimate.follow_target:
        return  # a bake's own frames
    moved = None
    if depsgraph is not None:
        moved = {update.id.original for update in depsgraph.updates if isinstance(update.id, bpy.types.Object)}
        if not moved:
            return
    now = _state["moved"] = time.monotonic()
    if now - _state["last"] < THROTTLE:
        if not _state["pending"]:
            _state["pending"] = True
            _wait(_follow_later, THROTTLE - (now - _state["last"]))
        return
    if follow(scene, moved, preview=True):
        _state["last"] = now
        _wait(_settle_later, REST)


@bpy.app.handlers.persistent
def _on_load(*_):
    """A file loaded: nothing of the last file's drags is kept."""
    _previewed.clear()
    reports.clear()
    generate.forget_reads()


def note(obj):
    """Why Follow Target stopped for the armature's last target gesture, or ""."""
    gesture = None if obj is None or obj.type != "ARMATURE" else gestures.last_targeted(obj)
    return "" if gesture is None else gesture.record["note"]


class RLANIMATE_OT_follow_target_report(bpy.types.Operator):
    """Report why Follow Target stopped following a gesture"""
    bl_idname = "rlanimate.follow_target_report"
    bl_label = "Follow Target Report"
    bl_options = {"INTERNAL"}

    message: bpy.props.StringProperty(options={"SKIP_SAVE"})

    def execute(self, context):
        self.report({"WARNING"}, self.message)
        return {"FINISHED"}


def register():
    bpy.utils.register_class(RLANIMATE_OT_follow_target_report)
    if _on_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(_on_update)
    if _on_load not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_on_load)


def unregister():
    if _on_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_on_update)
    if _on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_on_load)
    for function in (_follow_later, _settle_later, _flush_reports):
        if bpy.app.timers.is_registered(function):
            bpy.app.timers.unregister(function)
    _state.update(pending=False)
    _on_load()
    bpy.utils.unregister_class(RLANIMATE_OT_follow_target_report)
