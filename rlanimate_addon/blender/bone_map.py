"""Save Bone Map: write the active armature's bone map (detected or loaded) as a JSON file to edit and load."""
import bpy
from bpy_extras.io_utils import ExportHelper

from ..core import rig_roles
from ..core.errors import RLAnimateError
from . import armature_io, properties


def save_bone_map(context, filepath):
    """Write the bone map of the active armature to filepath; returns a one-line summary."""
    obj = context.active_object
    family, roles = armature_io.rig_roles_of(obj, properties.panel_settings(context).bone_map_file)
    path = bpy.path.abspath(filepath)
    try:
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(rig_roles.bone_map_json(family, roles))
    except OSError as error:
        raise RLAnimateError(f"Could not write {path} ({error.strerror}): choose a folder you can write to.") from None
    missing = [r for r in rig_roles.ROLES if r not in roles]
    needed = ([] if any(r in roles for r in rig_roles.SPINE) else ["Spine"]) + [
        r for r in dict.fromkeys(rig_roles.required_roles("LEFT") + rig_roles.required_roles("RIGHT")) if r in missing]
    found = f"{len(roles)} of {len(rig_roles.ROLES)} roles found"
    if not missing:
        return f"Saved the {family} bone map of {obj.name!r} ({found}) to {path}"
    return (f"Saved the {family} bone map of {obj.name!r} ({found}) to {path}: the other {len(missing)} are written as "
            f'"" to fill in' + (f", of which a gesture needs {', '.join(needed)}" if needed else ""))


class RLANIMATE_OT_save_bone_map(bpy.types.Operator, ExportHelper):
    """Write the active armature's bone map as a JSON file: fill in missing roles, then pick it as Bone Map"""
    bl_idname = "rlanimate.save_bone_map"
    bl_label = "Save Bone Map"
    bl_options = {"REGISTER"}

    filename_ext = ".json"
    filter_glob: bpy.props.StringProperty(default="*.json", options={"HIDDEN"})

    def execute(self, context):
        try:
            summary = save_bone_map(context, self.filepath)
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, summary)
        return {"FINISHED"}
