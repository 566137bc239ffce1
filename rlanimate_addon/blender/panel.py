"""The N-panel: View3D > Sidebar > RLAnimate."""
import os

import bpy

from ..core import behaviours, frame_rate, gesture
from ..core.errors import RLAnimateError
from . import armature_io, constraints, follow_target, preferences, properties, vrm_map


def _agent_summary(context, behaviour):
    """(label, error): the agent's name and its learned lengths for the behaviour in scene frames, or why
    it won't load."""
    path = preferences.selected_agent_path(context)
    name = "Bundled default" if path == preferences.BUNDLED_AGENT else path.name
    try:
        agent = preferences.selected_agent(context)
    except RLAnimateError as error:
        return name, str(error)
    if behaviour not in agent.behaviours:
        lacking = f"This agent does not perform {behaviours.title(behaviour)}" if behaviour else \
            "The chosen behaviour is not one of this agent's"
        return name, (f"{lacking} (it performs {', '.join(behaviours.title(b) for b in agent.behaviours)}): pick "
                      "one above, or choose an agent trained for it in Preferences.")
    average = agent.average_frames[behaviour]
    fps = properties.scene_fps(context.scene)
    average, shortest, longest = (frame_rate.scene_frames(n, fps)
                                  for n in (average, *gesture.supported_length_range(average)))
    return f"{name}: learned {average} frames, supported {shortest}-{longest}", None


def _overriding_constraints(context, settings, behaviour):
    """Constraints of the active armature that would override the gesture (empty for other objects)."""
    obj = context.active_object
    if obj is None or obj.type != "ARMATURE":
        return []
    return constraints.against_gesture(obj, constraints.driven_bones(_rig_roles(obj, settings.bone_map_file),
                                                                     behaviour, settings.arm))


_roles = {}


def _rig_roles(obj, bone_map_file):
    """The armature's roles as Generate finds them ({} when it cannot: Generate names why), remembered per
    bone names, bone-map and VRM file versions and VRM add-on map: detecting them takes about 1 ms, too
    long for every redraw."""
    paths = tuple(bpy.path.abspath(p) if p else "" for p in (bone_map_file, obj.rlanimate.vrm_file))
    key = (tuple(bone.name for bone in obj.data.bones), paths, tuple(_version(p) for p in paths),
           _vrm_addon_map(obj))
    if key not in _roles:
        _roles.clear()
        try:
            _roles[key] = armature_io.rig_roles_of(obj, bone_map_file)[1]
        except RLAnimateError:
            _roles[key] = {}
    return _roles[key]


def _version(path):
    """A file's modification time (None when absent or unreadable), to notice an edited map."""
    try:
        return os.stat(path).st_mtime_ns if path else None
    except OSError:
        return None


def _vrm_addon_map(obj):
    """The VRM add-on's humanoid map on the armature, as a hashable value (None without the add-on)."""
    roles = vrm_map.addon_roles(obj.data, set(obj.data.bones.keys()))
    return tuple(sorted(roles.items())) if roles else None


class VIEW3D_PT_rlanimate(bpy.types.Panel):
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "RLAnimate"
    bl_label = "RLAnimate"

    def draw(self, context):
        layout = self.layout
        settings = properties.panel_settings(context)
        obj = context.active_object
        if obj is not None and obj.type == "ARMATURE":
            layout.prop(obj.rlanimate, "use_own_settings", text=f"Own Settings for {obj.name}")
        layout.prop(settings, "behaviour", expand=True)
        layout.prop(settings, "arm", expand=True)
        behaviour = properties.chosen_behaviour(settings, context)
        kind = properties.behaviour_kind(context, behaviour)
        if kind == behaviours.TARGET:
            layout.prop(settings, "target")
            if settings.target is None:
                layout.prop(settings, "use_cursor")
            elif settings.target.type == "ARMATURE":
                layout.prop_search(settings, "target_bone", settings.target.data, "bones")
            if behaviour == behaviours.POINT:
                layout.prop(settings, "exact_aim")
        elif kind == behaviours.INTENSITY:
            layout.prop(settings, "exaggeration", slider=True)
            if behaviour == behaviours.WAVE:
                layout.prop(settings, "tempo", text="Tempo (Hz)")

        column = layout.column(align=True)
        row = column.row(align=True)
        row.prop(settings, "frame_count")
        row.label(text=f"{frame_rate.seconds(settings.frame_count, properties.scene_fps(context.scene)):.2f} s")
        column.prop(settings, "start_frame")
        column.prop(settings, "seed")

        layout.prop(settings, "blend_type", expand=True)
        row = layout.row(align=True)
        row.prop(settings, "keep_previous")
        row.prop(context.scene.rlanimate, "follow_target")
        stopped = follow_target.note(obj) if context.scene.rlanimate.follow_target else ""
        if stopped:
            layout.box().label(text=stopped, icon="INFO")
        row = layout.row(align=True)
        row.prop(settings, "editable_keys")
        if settings.editable_keys:
            row.prop(settings, "key_tolerance")
        row = layout.row(align=True)
        row.prop(settings, "bone_map_file")
        row.operator("rlanimate.save_bone_map", text="", icon="FILE_TICK")
        if obj is not None and obj.type == "ARMATURE":
            row = layout.row(align=True)
            row.operator("rlanimate.bone_map_from_vrm", icon="ARMATURE_DATA")
            if obj.rlanimate.vrm_file:
                row.prop(obj.rlanimate, "vrm_file", text="")

        label, error = _agent_summary(context, behaviour)
        box = layout.box()
        box.label(text=label, icon="INFO")
        if error:
            box.label(text=error, icon="ERROR")

        layout.operator("rlanimate.generate_gesture", icon="ARMATURE_DATA")
        overriding = _overriding_constraints(context, settings, behaviour)
        if overriding:
            box = layout.box()
            box.label(text=f"{constraints.describe(overriding)} would override the gesture", icon="ERROR")
            box.operator("rlanimate.generate_gesture", text="Generate, Muting Constraints",
                         icon="CONSTRAINT_BONE").mute_constraints = True
        layout.operator("rlanimate.export_fbx", icon="EXPORT")
