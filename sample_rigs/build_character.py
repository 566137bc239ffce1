"""Build the sample character from the canonical skeleton: `sample_rigs/character.blend` and `.fbx`.

Run as `python sample_rigs/build_character.py [OUT_DIR]` or `blender -b -P sample_rigs/build_character.py
-- [OUT_DIR]`. The armature "RLAnimate_Character" is `core.skeleton.BONES` exactly (names prefixed
`mixamorig:`, heads, tails, rolls from the z hints, parents, connected where a child starts at its
parent's tail); the mesh is a low-poly body of one prism per bone, rigidly skinned, so an animator
sees a figure. The output is deterministic: the same geometry, names and order on every run.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from rlanimate_addon.core import skeleton  # noqa: E402
from trainer import bpy_support  # noqa: E402

bpy = bpy_support.import_bpy()

RIG_NAME = bpy_support.SAMPLE_RIG_NAME
MESH_NAME = RIG_NAME + "_Body"
SIDES = 8  # vertices per prism ring

# Half-widths (m) of each bone's prism along the bone's local X and Z axes. The torso's X is the
# character's width and Z its depth; an arm's X is front-back and Z up-down. Unlisted bones
# (eyes, bone ends) get no prism.
_SECTIONS = {
    "Hips": (0.150, 0.100), "Spine": (0.140, 0.090), "Spine1": (0.150, 0.095), "Spine2": (0.160, 0.100),
    "Neck": (0.050, 0.050), "Head": (0.080, 0.095),
    "Shoulder": (0.050, 0.050), "Arm": (0.050, 0.050), "ForeArm": (0.040, 0.038), "Hand": (0.040, 0.016),
    "UpLeg": (0.075, 0.075), "Leg": (0.055, 0.055), "Foot": (0.045, 0.035), "ToeBase": (0.045, 0.025),
}
_FINGER_RADIUS = {"Thumb": 0.011, "Index": 0.009, "Middle": 0.0095, "Ring": 0.009, "Pinky": 0.008}
_EYE_RADIUS = 0.013


def _section(name):
    """(half-width along X, along Z) of the bone's prism, or None for no prism."""
    base = name[len("Left"):] if name.startswith("Left") else name[len("Right"):] if name.startswith("Right") else name
    if base in _SECTIONS:
        return _SECTIONS[base]
    for finger, radius in _FINGER_RADIUS.items():
        if base.startswith("Hand" + finger) and not base.endswith("4"):
            return radius, radius
    return None


def _prism(bone, half_x, half_z):
    """Vertices (2*SIDES, 3) and quad/ngon faces of a closed elliptic prism from the bone's head to tail."""
    frame = skeleton.rest_frame(bone)
    angles = 2.0 * np.pi * np.arange(SIDES) / SIDES
    ring = np.outer(half_x * np.cos(angles), frame[:, 0]) + np.outer(half_z * np.sin(angles), frame[:, 2])
    verts = np.concatenate([np.asarray(bone.head) + ring, np.asarray(bone.tail) + ring])  # (2*SIDES, 3)
    sides = [(k, (k + 1) % SIDES, SIDES + (k + 1) % SIDES, SIDES + k) for k in range(SIDES)]
    caps = [tuple(reversed(range(SIDES))), tuple(range(SIDES, 2 * SIDES))]
    return verts, sides + caps


def _octahedron(centre, radius):
    """A small diamond (6 vertices, 8 faces) at `centre`, for an eye."""
    axes = np.concatenate([np.eye(3), -np.eye(3)]) * radius
    faces = [(0, 1, 2), (1, 3, 2), (3, 4, 2), (4, 0, 2), (1, 0, 5), (3, 1, 5), (4, 3, 5), (0, 4, 5)]
    return np.asarray(centre) + axes, faces


def body_parts():
    """[(bone name, vertices (V, 3), faces)] of the body, in skeleton.BONES order."""
    parts = []
    for bone in skeleton.BONES:
        if bone.name.endswith("Eye"):
            parts.append((bone.name, *_octahedron(bone.head, _EYE_RADIUS)))
        elif (section := _section(bone.name)) is not None:
            parts.append((bone.name, *_prism(bone, *section)))
    return parts


def build_armature(scene):
    """Create the armature object of skeleton.BONES, linked to `scene`, in object mode."""
    data = bpy.data.armatures.new(RIG_NAME)
    obj = bpy.data.objects.new(RIG_NAME, data)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    edit_bones = {}
    for bone in skeleton.BONES:
        edit = data.edit_bones.new(skeleton.PREFIX + bone.name)
        edit.head, edit.tail = bone.head, bone.tail
        edit.align_roll(bone.z_hint)
        if bone.parent is not None:
            parent = skeleton.BONE_BY_NAME[bone.parent]
            edit.parent = edit_bones[bone.parent]
            edit.use_connect = bool(np.allclose(parent.tail, bone.head, atol=1e-6))
        edit_bones[bone.name] = edit
    bpy.ops.object.mode_set(mode="OBJECT")
    for pose_bone in obj.pose.bones:
        pose_bone.rotation_mode = "QUATERNION"
    return obj


def build_body(scene, rig):
    """Create the low-poly body mesh, rigidly skinned to `rig` with one vertex group per bone."""
    parts = body_parts()
    verts, faces, offset = [], [], 0
    for _, part_verts, part_faces in parts:
        verts.append(part_verts)
        faces += [tuple(offset + i for i in face) for face in part_faces]
        offset += len(part_verts)
    mesh = bpy.data.meshes.new(MESH_NAME)
    mesh.from_pydata(np.concatenate(verts).tolist(), [], faces)
    mesh.validate()
    obj = bpy.data.objects.new(MESH_NAME, mesh)
    scene.collection.objects.link(obj)
    obj.parent = rig
    offset = 0
    for name, part_verts, _ in parts:
        group = obj.vertex_groups.get(skeleton.PREFIX + name) or obj.vertex_groups.new(name=skeleton.PREFIX + name)
        group.add(list(range(offset, offset + len(part_verts))), 1.0, "REPLACE")
        offset += len(part_verts)
    modifier = obj.modifiers.new("Armature", "ARMATURE")
    modifier.object = rig
    return obj


def export_fbx(path):
    """Export the scene as a Mixamo-style FBX: -Z forward, Y up, no leaf bones, metres on re-import."""
    bpy.ops.export_scene.fbx(
        filepath=str(path), object_types={"ARMATURE", "MESH"}, add_leaf_bones=False,
        axis_forward="-Z", axis_up="Y", apply_unit_scale=True, apply_scale_options="FBX_SCALE_NONE",
        primary_bone_axis="Y", secondary_bone_axis="X", bake_anim=False, mesh_smooth_type="FACE",
        use_armature_deform_only=False)


def build(out_dir=Path(__file__).resolve().parent):
    """Build the character in a fresh scene and write character.blend and character.fbx to `out_dir`."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    scene = bpy_support.new_empty_scene()
    rig = build_armature(scene)
    build_body(scene, rig)
    bpy.ops.wm.save_as_mainfile(filepath=str(out_dir / "character.blend"), compress=True, copy=True)
    export_fbx(out_dir / "character.fbx")
    return rig


if __name__ == "__main__":
    args = bpy_support.script_args()
    build(*args[:1])
