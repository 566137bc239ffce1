"""The N-panel: View3D > Sidebar > RLAnimate."""
import os

import bpy

from ..core import behaviours, frame_rate, gesture, rig_roles, vrm
from ..core.errors import RLAnimateError
from . import (
    action_adapter,
    armature_io,
    constraints,
    follow_target,
    gesture_list,
    gestures,
    preferences,
    properties,
    vrm_map,
)


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


def _overriding_constraints(context, obj, settings, behaviour):
    """Constraints of the armature (None: no armature) that would override the gesture."""
    if obj is None:
        return []
    selected = gestures.find(obj, gestures.selected(obj))
    still = selected.still if selected is not None else not action_adapter.is_animated(obj)
    declared = properties.declared_behaviour(context, behaviour)
    return constraints.against_gesture(obj, constraints.driven_bones(_rig_roles(obj, settings.bone_map_file)[1],
                                                                     declared, settings.arm, still))


#: `_rig_roles`' one remembered armature: {(bone names, paths, versions, VRM add-on map, known): (family, roles)}.
_roles: dict[tuple[object, ...], tuple[str, dict[str, str]]] = {}
#: Bone namings that tell an armature imported from a VRM file.
_VRM_FAMILIES = {vrm.FAMILY, rig_roles.VROID.name, rig_roles.VRM_HUMANOID.name, rig_roles.VRM_ADDON.name}


def _rig_roles(obj, bone_map_file):
    """(family, roles) of the armature as Generate finds them (("", {}) when it cannot: Generate names why),
    remembered per bone names, bone-map and VRM file versions and VRM add-on map: detecting them takes about
    1 ms, too long for every redraw. A VRM file is never read here, only looked up where an operator read it."""
    paths = tuple(bpy.path.abspath(p) if p else "" for p in (bone_map_file, obj.rlanimate.vrm_file))
    key = (tuple(bone.name for bone in obj.data.bones), paths, tuple(_version(p) for p in paths),
           _vrm_addon_map(obj), vrm_map.known(paths[1]))
    if key not in _roles:
        _roles.clear()
        try:
            _roles[key] = armature_io.rig_roles_of(obj, bone_map_file, read_vrm=False)
        except RLAnimateError:
            _roles[key] = ("", {})
    return _roles[key]


def _offers_vrm_map(obj, settings):
    """Whether the panel offers Bone Map from VRM File for the armature: it came from a VRM file (its VRM File
    is kept, as the glTF import keeps it, the VRM add-on's map is on it, or its bones have VRoid's or VRM's
    humanoid names), or Generate cannot map its bones (its refusal offers the VRM file's map first)."""
    family, roles = _rig_roles(obj, settings.bone_map_file)
    if obj.rlanimate.vrm_file or family in _VRM_FAMILIES:
        return True
    try:
        rig_roles.check_roles(obj.name, roles, settings.arm, family)
    except RLAnimateError:
        return True
    return False

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
        obj = properties.armature_of(context.active_object)
        if obj is not None:
            layout.prop(obj.rlanimate, "use_own_settings", text=f"Own Settings for {obj.name}")
        behaviour = _draw_gesture_settings(layout, context, settings)
        _draw_options(layout, context, settings, obj)
        label, error = _agent_summary(context, behaviour)
        box = layout.box()
        box.label(text=label, icon="INFO")
        if error:
            box.label(text=error, icon="ERROR")
        selected = gestures.selected(obj) if obj is not None else ""
        layout.operator("rlanimate.generate_gesture", icon="ARMATURE_DATA",
                        text=f"Generate Again: {selected}" if selected else "Generate Gesture")
        overriding = _overriding_constraints(context, obj, settings, behaviour)
        if overriding:
            box = layout.box()
            box.label(text=f"{constraints.describe(overriding)} would override the gesture", icon="ERROR")
            box.operator("rlanimate.generate_gesture", text="Generate, Muting Constraints",
                         icon="CONSTRAINT_BONE").mute_constraints = True
        if obj is not None:
            gesture_list.draw(layout, context, obj)
        layout.operator("rlanimate.export_fbx", icon="EXPORT")


def _draw_gesture_settings(layout, context, settings):
    """The behaviour, arm, its target or exaggeration, length, start and seed; returns the behaviour chosen."""
    layout.prop(settings, "behaviour", expand=True)
    layout.prop(settings, "arm", expand=True)
    behaviour = properties.chosen_behaviour(settings, context)
    declared = properties.declared_behaviour(context, behaviour)
    kind = None if declared is None else declared.kind
    if kind == behaviours.TARGET:
        layout.prop(settings, "target")
        if settings.target is None:
            layout.prop(settings, "use_cursor")
        elif settings.target.type == "ARMATURE":
            layout.prop_search(settings, "target_bone", settings.target.data, "bones")
        if declared.aims:
            layout.prop(settings, "exact_aim")
    elif kind == behaviours.INTENSITY:
        layout.prop(settings, "exaggeration", slider=True)
        if declared.oscillates:
            layout.prop(settings, "tempo", text="Tempo (Hz)")
    column = layout.column(align=True)
    row = column.row(align=True)
    row.prop(settings, "frame_count")
    row.label(text=f"{frame_rate.seconds(settings.frame_count, properties.scene_fps(context.scene)):.2f} s")
    column.prop(settings, "start_frame")
    column.prop(settings, "seed")
    return behaviour


def _draw_options(layout, context, settings, obj):
    """How the gesture is layered and keyed, and the bone map."""
    layout.prop(settings, "blend_type", expand=True)
    row = layout.row(align=True)
    row.prop(settings, "keep_previous")
    row.prop(settings, "replace_edited_keys")
    layout.prop(context.scene.rlanimate, "follow_target")
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
    if obj is not None and _offers_vrm_map(obj, settings):
        row = layout.row(align=True)
        row.operator("rlanimate.bone_map_from_vrm", icon="ARMATURE_DATA")
        if obj.rlanimate.vrm_file:
            row.prop(obj.rlanimate, "vrm_file", text="")
