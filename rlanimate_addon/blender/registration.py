"""Registration in one place: the ordered class list and the property namespaces (Scene and Object)."""
import bpy

from . import bone_map, export, follow_target, generate, gesture_list, panel, preferences, properties, vrm_map

#: Registered in this order, unregistered in reverse (property groups before what points at them).
CLASSES = (
    preferences.RLANIMATE_AP_preferences,
    properties.RLANIMATE_PG_settings,
    properties.RLANIMATE_PG_object,
    generate.RLANIMATE_OT_generate_gesture,
    gesture_list.RLANIMATE_OT_select_gesture,
    gesture_list.RLANIMATE_OT_delete_gesture,
    gesture_list.RLANIMATE_OT_extend_scene_end,
    export.RLANIMATE_OT_export_fbx,
    bone_map.RLANIMATE_OT_save_bone_map,
    vrm_map.RLANIMATE_OT_bone_map_from_vrm,
    panel.VIEW3D_PT_rlanimate,
)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.rlanimate = bpy.props.PointerProperty(type=properties.RLANIMATE_PG_settings)
    bpy.types.Object.rlanimate = bpy.props.PointerProperty(type=properties.RLANIMATE_PG_object)
    follow_target.register()


def unregister():
    follow_target.unregister()
    del bpy.types.Object.rlanimate
    del bpy.types.Scene.rlanimate
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
