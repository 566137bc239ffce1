"""A VRM character's own humanoid map: from its .vrm file (core.vrm), or from the VRM add-on's data.

An armature imported with Blender's glTF importer carries nothing of the VRM: "Bone Map from VRM File"
reads the file's map, checks it against the armature's bones and keeps the file's path on the
armature (`Object.rlanimate.vrm_file`), where Generate finds it. An armature the VRM add-on imported
or set up carries the map itself (`Armature.vrm_addon_extension`), read here without importing the
add-on.
"""
import bpy
from bpy_extras.io_utils import ImportHelper

from ..core import vrm
from ..core.errors import RLAnimateError


def roles_of(obj):
    """{role: bone name} from the armature's VRM file or the VRM add-on's map, or None when it has neither."""
    names = [bone.name for bone in obj.data.bones]
    path = obj.rlanimate.vrm_file
    if path:
        return vrm.file_roles(bpy.path.abspath(path), names, repr(obj.name))
    return addon_roles(obj.data, set(names))


def addon_roles(armature, bone_names):
    """{role: bone name} of the VRM add-on's humanoid map on armature data (VRM 1.0 first, then 0.x), or
    None when the add-on left no map (or is not installed): only bones the armature has count."""
    extension = getattr(armature, "vrm_addon_extension", None)
    if extension is None:
        return None
    found = {}
    human_bones = getattr(getattr(getattr(extension, "vrm1", None), "humanoid", None), "human_bones", None)
    if human_bones is not None:
        found["1"] = {name: _bone_name(getattr(human_bones, vrm.snake_case(name), None))
                      for name in vrm.ROLE_OF["1"]}
    listed = getattr(getattr(getattr(extension, "vrm0", None), "humanoid", None), "human_bones", ())
    found["0"] = {str(getattr(entry, "bone", "")): _bone_name(entry) for entry in listed}
    for major in ("1", "0"):
        roles = vrm.roles_from_map(major, {k: b for k, b in found.get(major, {}).items() if b in bone_names})
        if roles:
            return roles
    return None


def _bone_name(human_bone):
    """The bone name a VRM add-on human bone points at ("" when unset)."""
    node = getattr(human_bone, "node", None)
    return str(getattr(node, "bone_name", "") or "")


class RLANIMATE_OT_bone_map_from_vrm(bpy.types.Operator, ImportHelper):
    """Map the active armature's bones from the humanoid map of the VRM file it was imported from"""
    bl_idname = "rlanimate.bone_map_from_vrm"
    bl_label = "Bone Map from VRM File"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".vrm"
    filter_glob: bpy.props.StringProperty(default="*.vrm;*.glb", options={"HIDDEN"})

    def execute(self, context):
        obj = context.active_object
        if obj is None or obj.type != "ARMATURE":
            self.report({"ERROR"}, "The active object is not an armature: select the character's armature.")
            return {"CANCELLED"}
        try:
            roles = vrm.file_roles(bpy.path.abspath(self.filepath), [b.name for b in obj.data.bones],
                                   repr(obj.name))
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        obj.rlanimate.vrm_file = self.filepath
        self.report({"INFO"}, f"{obj.name!r} now maps {len(roles)} roles from the VRM file {self.filepath}")
        return {"FINISHED"}
