"""A VRM character's own humanoid map: from its .vrm file (core.vrm), or from the VRM add-on's data.

Blender's glTF importer keeps nothing of the VRM, so while this add-on is enabled each armature it
imports from a file with a VRM humanoid keeps the file's path (`Object.rlanimate.vrm_file`, set by
`remember_vrm_file` from the importer's hook), where Generate finds it; for an armature imported
before, "Bone Map from VRM File" reads the file's map, checks it against the armature's bones and
keeps its path. An armature the VRM add-on imported or set up carries the map itself
(`Armature.vrm_addon_extension`), read here without importing the add-on.

A file's map, or why it cannot be read, is kept per path, modification time and size (`file_map`):
operators read the file (Generate, Save Bone Map, Bone Map from VRM File, the import), the panel's
draw() only looks up what they read (`roles_of(obj, read=False)`), never the file itself.
"""
import contextlib

import bpy
from bpy_extras.io_utils import ImportHelper

from ..core import vrm
from ..core.errors import RLAnimateError
from . import file_versions

#: The bone maps of the VRM files read, per file version.
_maps = file_versions.PerVersion(kept=16)


def file_map(path, read=True):
    """{role: bone name} of the VRM file at `path` (core.vrm.file_map), read once per version of the file;
    RLAnimateError when it cannot be read (the same message each time). With read=False (in draw()) the
    file is never read: None when no operator read this version of it yet."""
    return _maps.read(path, vrm.file_map, read)


def known(path):
    """Whether an operator has read this version of the file at `path` (its map or why it cannot be)."""
    return _maps.known(path)


def roles_of(obj, read=True):
    """{role: bone name} from the VRM add-on's map on the armature (kept up to date as bones are
    renamed), else from its VRM file, or None when it has neither. read=False (in draw()): the file is
    not read; RLAnimateError when no operator has read it yet."""
    names = obj.data.bones.keys()
    roles = addon_roles(obj.data, set(names))
    path = obj.rlanimate.vrm_file
    if roles:
        vrm.check_one_role_per_bone(roles, f"The VRM add-on's humanoid map of {obj.name!r}", "generate again")
    if roles or not path:
        return roles
    try:
        roles = file_map(bpy.path.abspath(path), read)
        if roles is None:
            raise RLAnimateError(f"The VRM file of {obj.name!r} is read when the gesture is generated.")
        vrm.check_bones(roles, names, bpy.path.abspath(path), repr(obj.name))
    except RLAnimateError as error:
        raise RLAnimateError(f"{error} (Armature {obj.name!r} takes its bone map from that VRM file: pick the "
                             "right one with 'Bone Map from VRM File', or clear its VRM File field in the RLAnimate "
                             "panel to detect the bones by name.)") from None
    return roles


def remember_vrm_file(gltf):
    """Keep the path of a VRM file on the armatures Blender's glTF importer made from it (`gltf`: the
    importer's state, after its nodes are created); a glTF without a VRM humanoid is left alone."""
    extensions = getattr(gltf.data, "extensions", None) or {}
    if "VRMC_vrm" not in extensions and "VRM" not in extensions:
        return
    for vnode in getattr(gltf, "vnodes", {}).values():
        obj = getattr(vnode, "blender_object", None)
        if obj is not None and obj.type == "ARMATURE":
            obj.rlanimate.vrm_file = gltf.filename
            with contextlib.suppress(RLAnimateError):  # read now, in the import, for the panel; Generate reports it
                file_map(gltf.filename)


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
        path = bpy.path.abspath(self.filepath)
        try:
            roles = file_map(path)
            vrm.check_bones(roles, obj.data.bones.keys(), path, repr(obj.name))
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        obj.rlanimate.vrm_file = self.filepath
        self.report({"INFO"}, f"{obj.name!r} now maps {len(roles)} roles from the VRM file {self.filepath}")
        return {"FINISHED"}
