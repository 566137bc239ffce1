"""Build the sample character from the canonical skeleton: `sample_rigs/character.blend` and `.fbx`.

Run as `python sample_rigs/build_character.py [OUT_DIR]` or `blender -b -P sample_rigs/build_character.py
-- [OUT_DIR]`. Write the committed files with Blender 4.2 LTS (`.venv-bpy42/bin/python ...`): 4.2
cannot read a .blend saved by 5.0. The armature "RLAnimate_Character" is `core.skeleton.BONES` exactly
(names prefixed `mixamorig:`, heads, tails, rolls from the z hints, parents, connected where a child
starts at its parent's tail); the mesh is a low-poly mannequin (a tapered prism per bone, ellipsoids for the skull,
eyes and joints), rigidly skinned, so an animator sees a body. The content is deterministic: the same
bones, vertices, faces and weights in the same order on every run (the bytes are not: Blender stores
some memory addresses in the .blend, and the FBX exporter a creation time).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from rlanimate_addon.core import skeleton  # noqa: E402
from trainer.blender_io import rig_session  # noqa: E402
from trainer.scripts.cli import script_args  # noqa: E402

bpy = rig_session.import_bpy()

RIG_NAME = rig_session.SAMPLE_RIG_NAME
MESH_NAME = RIG_NAME + "_Body"
# Half-widths (m) of each bone's prism along the bone's local X and Z axes at its head, and the
# factor they scale by at its tail. The torso's X is the character's width and Z its depth; a limb's
# X is front-back and Z up-down. Bones without an entry (eyes, bone ends) get no prism.
_SECTIONS = {
    "Hips": (0.140, 0.095, 1.05), "Spine": (0.135, 0.090, 1.05), "Spine1": (0.140, 0.095, 1.10),
    "Spine2": (0.155, 0.100, 0.75), "Neck": (0.045, 0.045, 1.0),
    "Shoulder": (0.045, 0.050, 1.0), "Arm": (0.050, 0.050, 0.80), "ForeArm": (0.040, 0.040, 0.75),
    "Hand": (0.040, 0.016, 1.0),
    "UpLeg": (0.080, 0.080, 0.70), "Leg": (0.055, 0.055, 0.65), "Foot": (0.040, 0.035, 1.1),
    "ToeBase": (0.045, 0.025, 0.8),
}
_FINGER_RADIUS = {"Thumb": 0.011, "Index": 0.009, "Middle": 0.0095, "Ring": 0.009, "Pinky": 0.008}
# Ellipsoids (bone, centre offset from the bone's head in armature axes, radii along the bone's X, Y, Z):
# the skull, and balls that round off the joints where prisms meet.
_ELLIPSOIDS = [("Head", (0.0, 0.005, 0.105), (0.080, 0.115, 0.095))] + [
    (side + bone, (0.0, 0.0, 0.0), (radius, radius, radius))
    for side in ("Left", "Right")
    for bone, radius in (("Arm", 0.052), ("ForeArm", 0.042), ("Hand", 0.032), ("Leg", 0.058), ("Foot", 0.042))]
_EYE_RADIUS = 0.013
SIDES = 8  # vertices per ring


def _section(name):
    """(half-width along X, along Z, taper) of the bone's prism, or None for no prism."""
    base = name.removeprefix("Left").removeprefix("Right")
    if base in _SECTIONS:
        return _SECTIONS[base]
    for finger, radius in _FINGER_RADIUS.items():
        if base.startswith("Hand" + finger) and not base.endswith("4"):
            return radius, radius, 0.9
    return None


def _prism(bone, half_x, half_z, taper):
    """Vertices (2*SIDES, 3) and faces of a closed elliptic prism from the bone's head to its tail."""
    frame = skeleton.rest_frame(bone)
    angles = 2.0 * np.pi * np.arange(SIDES) / SIDES
    ring = np.outer(half_x * np.cos(angles), frame[:, 0]) + np.outer(half_z * np.sin(angles), frame[:, 2])
    verts = np.concatenate([np.asarray(bone.head) + ring, np.asarray(bone.tail) + taper * ring])  # (2*SIDES, 3)
    sides = [(k, (k + 1) % SIDES, SIDES + (k + 1) % SIDES, SIDES + k) for k in range(SIDES)]
    caps = [tuple(reversed(range(SIDES))), tuple(range(SIDES, 2 * SIDES))]
    return verts, sides + caps


def _ellipsoid(centre, axes, rings=5):
    """Vertices and faces of a low-poly ellipsoid; `axes` (3, 3) holds its semi-axes as columns."""
    polar = np.pi * np.arange(1, rings) / rings  # latitudes between the poles
    angles = 2.0 * np.pi * np.arange(SIDES) / SIDES
    unit = [(0.0, 0.0, -1.0)] + [(np.sin(p) * np.cos(a), np.sin(p) * np.sin(a), -np.cos(p))
                                 for p in polar for a in angles] + [(0.0, 0.0, 1.0)]
    verts = np.asarray(centre) + np.asarray(unit) @ np.asarray(axes).T
    top = len(unit) - 1
    faces = [(0, 1 + (k + 1) % SIDES, 1 + k) for k in range(SIDES)]
    for r in range(rings - 2):
        low, high = 1 + r * SIDES, 1 + (r + 1) * SIDES
        faces += [(low + k, low + (k + 1) % SIDES, high + (k + 1) % SIDES, high + k) for k in range(SIDES)]
    last = 1 + (rings - 2) * SIDES
    faces += [(last + k, last + (k + 1) % SIDES, top) for k in range(SIDES)]
    return verts, faces


def body_parts():
    """[(bone name, vertices (V, 3), faces)] of the body: prisms in skeleton.BONES order, then ellipsoids."""
    parts = []
    for bone in skeleton.BONES:
        if bone.name.endswith("Eye"):
            parts.append((bone.name, *_ellipsoid(bone.head, np.eye(3) * _EYE_RADIUS, rings=3)))
        elif (section := _section(bone.name)) is not None:
            parts.append((bone.name, *_prism(bone, *section)))
    for name, offset, radii in _ELLIPSOIDS:
        bone = skeleton.BONE_BY_NAME[name]
        axes = skeleton.rest_frame(bone) * np.asarray(radii)
        parts.append((name, *_ellipsoid(np.add(bone.head, offset), axes)))
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


SAMPLE_RIGS_DIR = Path(__file__).resolve().parent


def build(out_dir=SAMPLE_RIGS_DIR):
    """Build the character in a fresh scene and write character.blend and character.fbx to `out_dir`."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    scene = rig_session.new_empty_scene()
    bpy.context.preferences.filepaths.save_version = 0  # no character.blend1 backup
    rig = build_armature(scene)
    build_body(scene, rig)
    bpy.ops.wm.save_as_mainfile(filepath=str(out_dir / "character.blend"), compress=True, copy=True)
    export_fbx(out_dir / "character.fbx")
    return rig


if __name__ == "__main__":
    args = script_args()
    build(*args[:1])
