"""Export FBX: the active armature, its meshes and its baked animation, through Blender's FBX exporter."""
import os
from contextlib import contextmanager
from pathlib import Path

import bpy
from bpy_extras.io_utils import ExportHelper

from ..core.errors import RLAnimateError, operator_error_reason

#: Settings a Mixamo-style consumer (Unity, Unreal, Mixamo itself) reads back as it was baked: no leaf
#: bones, Blender's bone axes, one take of the evaluated scene animation (NLA strips included),
#: a key on every frame and no curve simplification.
FBX_SETTINGS = dict(
    use_selection=True, object_types={"ARMATURE", "MESH"}, use_mesh_modifiers=False,
    add_leaf_bones=False, armature_nodetype="NULL", use_armature_deform_only=False,
    primary_bone_axis="Y", secondary_bone_axis="X", axis_forward="-Z", axis_up="Y",
    apply_unit_scale=True, apply_scale_options="FBX_SCALE_NONE", global_scale=1.0,
    bake_anim=True, bake_anim_use_all_bones=True, bake_anim_use_nla_strips=False,
    bake_anim_use_all_actions=False, bake_anim_force_startend_keying=True, bake_anim_step=1.0,
    bake_anim_simplify_factor=0.0, path_mode="AUTO",
)


class _OneFrameOn:
    """The scene as Blender's exporter sees it while it times the scene's take: frame_set(F) plays frame F + 1,
    so the exporter writes frame F + 1 at time F / fps. Everything else is the scene's."""

    def __init__(self, scene):
        self._scene = scene

    def frame_set(self, frame, subframe=0.0):
        self._scene.frame_set(frame + 1, subframe=subframe)

    def __getattr__(self, name):
        return getattr(self._scene, name)


@contextmanager
def take_at_own_frames(first, last):
    """Within this context Blender's exporter writes the scene's take over frames first-last with frame F at
    time (F - 1) / fps, which its importer, at its defaults (Animation Offset 1: time 0 on frame 1), puts back
    on frame F: every keyed frame plays at its own time whatever the scene's start (frames before 1 at
    negative times; the scene's own range cannot start below 0).

    The exporter writes a scene's take over the scene's range with frame F at time F / fps (a gesture baked
    from frame 1 came back one frame late, 8 cm at the sample's right hand), and has no option for another
    range or offset. Its one function that times a take, `fbx_animations_do`, is called for the scene's take
    with the range one frame earlier on a scene whose frame_set plays one frame on (`_OneFrameOn`), and the
    scene's frame put back; the exporter is left as it was on exit."""
    from io_scene_fbx import export_fbx_bin  # Blender's bundled FBX add-on (4.2 to 5.0)

    timed = export_fbx_bin.fbx_animations_do

    def at_own_frames(scene_data, ref_id, f_start, f_end, start_zero, *args, **kwargs):
        if ref_id is not None or start_zero:  # a strip's or an action's take: timed as the exporter times it
            return timed(scene_data, ref_id, f_start, f_end, start_zero, *args, **kwargs)
        scene = scene_data.scene
        frame, subframe = scene.frame_current, scene.frame_subframe
        try:
            # Sampled to half a frame past the end: the exporter's np.arange(start, nextafter(end)) drops the last
            # frame of a range starting below 0 (the nextafter is lost in the sum); the take keeps its true end.
            taken = timed(scene_data._replace(scene=_OneFrameOn(scene)), ref_id, first - 1, last - 0.5, False,
                          *args, **kwargs)
        finally:
            scene.frame_set(frame, subframe=subframe)
        return None if taken is None else (*taken[:-1], last - 1)  # (..., its first frame, its last frame)

    export_fbx_bin.fbx_animations_do = at_own_frames
    try:
        yield
    finally:
        export_fbx_bin.fbx_animations_do = timed


def rig_meshes(rig, scene):
    """Meshes deformed by, or parented to, the rig."""
    return [obj for obj in scene.objects if obj.type == "MESH" and (
        obj.parent == rig or any(m.type == "ARMATURE" and m.object == rig for m in obj.modifiers))]


def animation_range(rig):
    """(first, last) frame of the rig's active action and NLA strips, or None without animation."""
    data = rig.animation_data
    if data is None:
        return None
    ranges = [tuple(data.action.frame_range)] if data.action is not None else []
    ranges += [(s.frame_start, s.frame_end) for t in data.nla_tracks for s in t.strips]
    if not ranges:
        return None
    return int(min(r[0] for r in ranges)), int(round(max(r[1] for r in ranges)))


def check_path(filepath):
    """The absolute path to write, or RLAnimateError naming what is wrong with it."""
    if not filepath:
        raise RLAnimateError("No file chosen: give a path ending in .fbx.")
    if "\0" in filepath:
        raise RLAnimateError(f"The path {filepath!r} holds a NUL character: choose another file name.")
    path = Path(bpy.path.abspath(filepath))
    if path.is_dir():
        raise RLAnimateError(f"{path} is a folder: give a file name ending in .fbx.")
    if not path.parent.is_dir():
        raise RLAnimateError(f"The folder {path.parent} does not exist: choose an existing folder.")
    if not os.access(path.parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise RLAnimateError(f"Cannot write {path}: you lack write permission there. Choose a folder you can "
                             "write to.")
    return path


def export_rig(context, filepath):
    """Write the active armature and its meshes to `filepath`; returns a one-line summary.

    The take spans the scene's frame range widened to all of the rig's animation (take_at_own_frames); the
    selection is restored.
    """
    rig = context.active_object
    if rig is None or rig.type != "ARMATURE":
        raise RLAnimateError("The active object is not an armature: select the character's armature.")
    path = check_path(filepath)
    scene, view_layer = context.scene, context.view_layer
    objects = [rig] + rig_meshes(rig, scene)
    selected = [o for o in view_layer.objects if o.select_get()]
    first, last = scene.frame_start, scene.frame_end
    keyed = animation_range(rig)
    if keyed is not None:
        first, last = min(first, keyed[0]), max(last, keyed[1])
    try:
        for obj in selected:
            obj.select_set(False)
        for obj in objects:
            obj.select_set(True)
        with take_at_own_frames(first, last):
            bpy.ops.export_scene.fbx(filepath=str(path), **FBX_SETTINGS)
    except RuntimeError as error:
        raise RLAnimateError(f"Could not write {path}: {operator_error_reason(error)}. Choose a folder you can write "
                             "to.") from None
    finally:
        for obj in objects:
            obj.select_set(False)
        for obj in selected:
            obj.select_set(True)
    return (f"Exported {rig.name!r} with {len(objects) - 1} mesh(es), frames {first}-{last} each at its "
            f"own time, to {filepath}")


class RLANIMATE_OT_export_fbx(bpy.types.Operator, ExportHelper):
    """Export the active armature, its meshes and its baked gestures as a Mixamo-compatible FBX"""
    bl_idname = "rlanimate.export_fbx"
    bl_label = "Export FBX"
    bl_options = {"REGISTER"}

    filename_ext = ".fbx"
    filter_glob: bpy.props.StringProperty(default="*.fbx", options={"HIDDEN"})

    def execute(self, context):
        try:
            summary = export_rig(context, self.filepath)
        except RLAnimateError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, summary)
        return {"FINISHED"}
