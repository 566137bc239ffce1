"""Rig variants built from the sample character, as animators' characters come, and Blender's own human
metarig and a Rigify rig generated from it: each built once and saved as a .blend that a test appends
into its own fresh scene.

Each builder gets the sample character (armature and mesh) in an empty scene and returns the armature
to save; `tmp` is a folder for the files an export and re-import go through.
"""
import math

import bpy
import numpy as np

import addon_helpers as helpers
from rlanimate_addon.core import gesture, rig_roles, skeleton


def _edit(rig, change):
    helpers.activate(rig)
    bpy.ops.object.mode_set(mode="EDIT")
    change(rig.data.edit_bones)
    bpy.ops.object.mode_set(mode="OBJECT")


def no_eyes_no_index4(rig, tmp):
    def remove(bones):
        for name in ("LeftEye", "RightEye", "LeftHandIndex4", "RightHandIndex4"):
            bones.remove(bones[skeleton.PREFIX + name])
    _edit(rig, remove)
    return rig


def _rename(rig, new_name):
    for bone in rig.data.bones:
        bone.name = new_name(skeleton.strip_prefix(bone.name))
    return rig


def numbered_prefix(rig, tmp):
    return _rename(rig, lambda name: "mixamorig1:" + name)


def glued_prefix(rig, tmp):
    return _rename(rig, lambda name: "mixamorig" + name)


def _family_renamer(family):
    """Canonical name -> the family's name for its role (bones without a role keep theirs)."""
    def rename(name):
        templates = rig_roles._side_templates(family, name)
        return templates[0] if templates else name
    return rename


def rigify_named(rig, tmp):
    return _rename(rig, _family_renamer(rig_roles.RIGIFY))


def unreal_named(rig, tmp):
    return _rename(rig, _family_renamer(rig_roles.UNREAL))


def rigify_deform_named(rig, tmp):
    """Rigify's deform bones alone, as a game export of a Rigify rig has them (DEF-upper_arm.L, ...)."""
    return _rename(rig, _family_renamer(rig_roles.RIGIFY_DEFORM))


def biped_named(rig, tmp):
    """3ds Max Biped names with their spaces: 'Bip01 R UpperArm', 'Bip01 Spine1'."""
    family_name = _family_renamer(rig_roles.BIPED)

    def rename(name):
        new = family_name(name)
        if new == name:
            return name
        return f"Bip01 {new[0]} {new[1:]}" if name.startswith(("Left", "Right")) else "Bip01 " + new
    return _rename(rig, rename)


def _select_only(objects):
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj in objects)


def _centimetre_fbx(rig, tmp, automatic_bone_orientation):
    """The armature in centimetres under an object scale of 0.01, exported to FBX and imported back."""
    def to_centimetres(bones):
        ends = {b.name: (b.head * 100.0, b.tail * 100.0) for b in bones}  # read all first: connected bones share ends
        for bone in bones:
            bone.head, bone.tail = ends[bone.name]
    _edit(rig, to_centimetres)
    rig.scale = (0.01, 0.01, 0.01)
    _select_only([rig])
    path = str(tmp / f"centimetres_{automatic_bone_orientation}.fbx")
    bpy.ops.export_scene.fbx(filepath=path, use_selection=True, object_types={"ARMATURE"}, add_leaf_bones=False,
                             bake_anim=False)
    before = set(bpy.data.objects)
    bpy.ops.import_scene.fbx(filepath=path, automatic_bone_orientation=automatic_bone_orientation)
    return next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")


def centimetre_fbx_automatic_orientation(rig, tmp):
    return _centimetre_fbx(rig, tmp, True)


def centimetre_fbx_plain_orientation(rig, tmp):
    return _centimetre_fbx(rig, tmp, False)


def _gltf(rig, tmp, heuristic):
    _select_only([rig] + [o for o in bpy.data.objects if o.parent is rig])
    path = str(tmp / f"character_{heuristic}.glb")
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", use_selection=True, export_animations=False)
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=path, bone_heuristic=heuristic)
    return next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")


def gltf_blender_bones(rig, tmp):
    return _gltf(rig, tmp, "BLENDER")


def gltf_temperance_bones(rig, tmp):
    return _gltf(rig, tmp, "TEMPERANCE")


def gltf_fortune_bones(rig, tmp):
    return _gltf(rig, tmp, "FORTUNE")


def euler_bones(rig, tmp):
    """Every bone in Euler XYZ, the arms in ZXY, one spine bone in axis-angle."""
    for bone in rig.pose.bones:
        name = skeleton.strip_prefix(bone.name)
        bone.rotation_mode = "ZXY" if name.endswith(("Arm", "ForeArm")) else "AXIS_ANGLE" if name == "Spine1" else "XYZ"
    return rig


def rotated_and_parented(rig, tmp):
    """The armature turned 35 degrees and scaled 1.3 under a parent that is turned and moved."""
    parent = helpers.add_empty("Stage", (2.0, -1.0, 0.5))
    parent.rotation_euler = (0.0, 0.0, math.radians(-50.0))
    rig.parent = parent
    rig.rotation_euler = (0.0, 0.0, math.radians(35.0))
    rig.scale = (1.3, 1.3, 1.3)
    return rig


#: Frames the idle animation covers.
IDLE_FRAMES = (1, 700)


def idle_animation(rig, tmp):
    """An idle: hips swaying side to side and turning, the spine breathing, the head nodding, the arms
    hanging and swinging a little; keyed every 4 frames."""
    bones = {name: rig.pose.bones[skeleton.PREFIX + name] for name in
             ("Hips", "Spine", "Spine1", "Spine2", "Head", "LeftArm", "RightArm", "LeftForeArm", "RightForeArm")}
    for frame in range(IDLE_FRAMES[0], IDLE_FRAMES[1] + 1, 4):
        sway, breath = math.sin(2 * math.pi * frame / 90.0), math.sin(2 * math.pi * frame / 60.0)
        bones["Hips"].location = (3.0 * sway * 0.01, 0.0, 0.01 * abs(sway))
        bones["Hips"].rotation_quaternion = _quat((0.0, 0.08 * sway, 0.0))
        for name, amount in (("Spine", 0.02), ("Spine1", 0.03), ("Spine2", 0.04)):
            bones[name].rotation_quaternion = _quat((amount * breath, 0.0, -0.03 * sway))
        bones["Head"].rotation_quaternion = _quat((0.05 * breath, 0.04 * sway, 0.0))
        for name in ("LeftArm", "RightArm", "LeftForeArm", "RightForeArm"):  # the sample's rest frames are canonical
            bones[name].rotation_quaternion = _quat(gesture.STANDING_POSE[name] + (0.06 * sway, 0.0, 0.03 * breath))
        for name, bone in bones.items():
            bone.keyframe_insert("rotation_quaternion", frame=frame)
            if name == "Hips":
                bone.keyframe_insert("location", frame=frame)
    return rig


def _quat(rotvec):
    from rlanimate_addon.core.rotations import rotvec_to_quat

    return tuple(rotvec_to_quat(np.asarray(rotvec, dtype=np.float64)))


def _blender_metarig():
    import addon_utils

    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    return bpy.context.active_object


def blender_human_metarig(rig, tmp):
    """Blender's own human metarig (Add > Armature > Human (Meta-Rig)), not built from the sample."""
    return _blender_metarig()


def generate_rigify(fingers=True):
    """(metarig, generated rig): Rigify's generation of Blender's human metarig without its face, and
    without its hands' palms and fingers unless `fingers`."""
    metarig = _blender_metarig()
    bpy.ops.object.mode_set(mode="EDIT")
    edit_bones = metarig.data.edit_bones
    cut = [edit_bones["face"]] + ([] if fingers else [b for b in edit_bones if b.name.startswith("palm.")])
    for bone in {b for top in cut for b in (top, *top.children_recursive)}:
        edit_bones.remove(bone)
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.pose.rigify_generate()
    return metarig, bpy.context.active_object


def rigify_generated(rig, tmp):
    """A real Rigify rig (410 bones: DEF-, ORG-, MCH- and controls) generated from Blender's human metarig
    without its face, its arms switched to FK. The face rig takes 6 s of the 6.2 s generation and adds no
    bone a gesture keys or the role detector finds (Rigify's eyes sit behind its face controls)."""
    generated = generate_rigify()[1]
    for side in ("L", "R"):
        generated.pose.bones["upper_arm_parent." + side]["IK_FK"] = 1.0
    return generated


BUILDERS = {f.__name__: f for f in (
    no_eyes_no_index4, numbered_prefix, glued_prefix, centimetre_fbx_automatic_orientation,
    centimetre_fbx_plain_orientation, gltf_blender_bones, gltf_temperance_bones, gltf_fortune_bones, euler_bones,
    rigify_named, unreal_named, rigify_deform_named, biped_named, rotated_and_parented, idle_animation,
    blender_human_metarig, rigify_generated)}


def build(name, folder):
    """Build the named variant in a fresh scene and save it to folder/<name>.blend; returns the path."""
    helpers.enable_addon()
    rig = BUILDERS[name](helpers.load_sample_rig(), folder)
    rig.name = "Variant"
    path = folder / f"{name}.blend"
    keep = {rig} | {o for o in bpy.data.objects if o.parent is rig} | ({rig.parent} if rig.parent else set())
    keep |= {o for o in bpy.data.objects if o.name.startswith("WGT")}  # Rigify's control shapes
    bpy.data.libraries.write(str(path), keep, fake_user=True)
    helpers.disable_addon()
    return path


def load(path):
    """Append the saved variant's objects into the scene; returns the armature."""
    with bpy.data.libraries.load(str(path), link=False) as (source, target):
        target.objects = list(source.objects)
    for obj in target.objects:
        bpy.context.scene.collection.objects.link(obj)
    return helpers.activate(bpy.data.objects["Variant"])
