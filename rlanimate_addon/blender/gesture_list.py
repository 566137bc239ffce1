"""The panel's list of the gestures on the active armature, and what it does: select a gesture (its settings
load into the panel, and Generate then bakes that one again), go back to adding a new one, delete one (its
keys only), and extend the scene's end over gestures that run past it."""
import bpy

from ..core import behaviours, composition
from ..core.errors import RLAnimateError
from . import constraints, generate, gestures, key_layers, properties

#: Recorded settings that are not a gesture's own, so selecting one does not load them.
_NOT_LOADED = {"follow_target"}


def _armature(context):
    obj = properties.armature_of(context.active_object)
    if obj is None:
        raise RLAnimateError("The active object is not an armature, nor a mesh an armature deforms: select the "
                             "character's armature or its mesh.")
    return obj


def load_settings(settings, recorded):
    """Set the settings group from a gesture's recorded settings; returns the names it could not set (a
    behaviour the selected agent lacks)."""
    skipped = []
    for name, value in recorded.to_dict().items():
        if name in _NOT_LOADED or name not in settings.bl_rna.properties:
            continue
        try:
            setattr(settings, name, value)
        except (TypeError, ValueError):
            skipped.append(name)
    return skipped


def delete(context, obj, name):
    """Delete the armature's gesture `name`: its own keys (keys others put in its actions stay), its constraint
    mutes given back; a base's standing pose stays while other gestures rest on it. The gestures that depended on
    it are baked again (generate.rebake). Returns the report line."""
    placed = gestures.find(obj, name)
    if placed is None:
        raise RLAnimateError(f"{obj.name!r} has no gesture {name!r}: it was deleted or renamed.")
    spans = [g.span for g in gestures.placed_gestures(obj)]
    depending = composition.dependants(spans, placed.span, None)
    constraints.unmute(obj, gestures.influence_before(placed))
    kept = placed.still and len(spans) > 1
    key_layers.remove(placed, keep_standing=kept)
    if obj.rlanimate.gesture == name:
        obj.rlanimate.gesture = ""
    standing = " (its standing pose stays under the other gestures: 'RLAnimate Standing Pose')" if kept else ""
    return f"Deleted {name!r} from {obj.name!r}, its keys only{standing}{generate.rebake(context, obj, depending)}"


class RLANIMATE_OT_select_gesture(bpy.types.Operator):
    """Select a gesture of the active armature: its settings load into the panel, and Generate bakes it again.
    With no gesture, Generate adds a new one from the current frame"""
    bl_idname = "rlanimate.select_gesture"
    bl_label = "Select Gesture"
    bl_options = {"REGISTER", "UNDO"}

    gesture: bpy.props.StringProperty(name="Gesture", default="",
                                      description="The gesture's name (its action's); empty: add a new gesture")

    def execute(self, context):
        try:
            obj = _armature(context)
            settings = properties.panel_settings(context)
            if not self.gesture:
                obj.rlanimate.gesture = ""
                properties.follow_playhead(settings)
                self.report({"INFO"}, "Generate adds a new gesture, from the current frame")
                return {"FINISHED"}
            placed = gestures.find(obj, self.gesture)
            if placed is None:
                raise RLAnimateError(f"{obj.name!r} has no gesture {self.gesture!r}: it was deleted or renamed.")
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        skipped = load_settings(settings, placed.record["settings"])
        obj.rlanimate.gesture = placed.name
        note = f" (not loaded: {', '.join(skipped)}, which the selected agent lacks)" if skipped else ""
        self.report({"WARNING"} if skipped else {"INFO"},
                    f"Selected {placed.name!r}: Generate bakes it again with the panel's settings{note}")
        return {"FINISHED"}


class RLANIMATE_OT_delete_gesture(bpy.types.Operator):
    """Delete a gesture of the active armature: its own keys only"""
    bl_idname = "rlanimate.delete_gesture"
    bl_label = "Delete Gesture"
    bl_options = {"REGISTER", "UNDO"}

    gesture: bpy.props.StringProperty(name="Gesture", default="", description="The gesture's name (its action's)")

    def execute(self, context):
        try:
            summary = delete(context, _armature(context), self.gesture)
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, summary)
        return {"FINISHED"}


def last_frame(obj):
    """The last frame of the armature's gestures (None without any)."""
    return max((int(g.record["end"]) for g in gestures.placed_gestures(obj)), default=None)


class RLANIMATE_OT_extend_scene_end(bpy.types.Operator):
    """Extend the scene's end to the last frame of the active armature's gestures"""
    bl_idname = "rlanimate.extend_scene_end"
    bl_label = "Extend Scene End"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        try:
            obj = _armature(context)
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        scene, last = context.scene, last_frame(obj)
        if last is None or last <= scene.frame_end:
            self.report({"INFO"}, f"The scene already ends at frame {scene.frame_end}, after every gesture")
            return {"CANCELLED"}
        scene.frame_end = last
        self.report({"INFO"}, f"The scene now ends at frame {last}, the last frame of {obj.name!r}'s gestures")
        return {"FINISHED"}


def _row_text(placed):
    """'Point Right 1-93 (to 50), seed 0, at Target' of a gesture."""
    record = placed.record
    recorded = record["settings"]
    text = f"{behaviours.title(record['behaviour'])} {record['arm'].title()} {record['start']}-{record['end']}"
    if "trim" in record:
        text += f" (to {record['trim']['at']})"
    text += f", seed {recorded.get('seed', 0)}"
    target = recorded.get("target")
    if record.get("kind") == behaviours.TARGET:
        bone = recorded.get("target_bone", "") if target is not None and target.type == "ARMATURE" else ""
        text += f", at {target.name + (':' + bone if bone else '') if target is not None else '3D cursor'}"
    return text


def draw(layout, context, obj):
    """The list of the armature's gestures in timeline order: select one, delete one; an edited one marked."""
    placed = gestures.in_timeline_order(obj)
    box = layout.box()
    row = box.row()
    row.label(text=f"Gestures on {obj.name}" if placed else f"No gestures on {obj.name} yet", icon="NLA")
    selected = gestures.selected(obj)
    if selected:
        row.operator("rlanimate.select_gesture", text="New", icon="ADD").gesture = ""
    for gesture in placed:
        edited = gestures.edited_lately(gesture)
        row = box.row(align=True)
        row.operator("rlanimate.select_gesture", text=_row_text(gesture) + (", edited by hand" if edited else ""),
                     icon="GREASEPENCIL" if edited else "ARMATURE_DATA",
                     depress=gesture.name == selected).gesture = gesture.name
        row.operator("rlanimate.delete_gesture", text="", icon="X").gesture = gesture.name
    last = last_frame(obj)
    if last is not None and last > context.scene.frame_end:
        box.label(text=f"Gestures run to frame {last}, past the scene's end ({context.scene.frame_end})",
                  icon="ERROR")
        box.operator("rlanimate.extend_scene_end", icon="PREVIEW_RANGE")
