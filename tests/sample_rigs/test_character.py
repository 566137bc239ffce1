"""The committed sample character matches the canonical skeleton, re-imports from FBX, and is reproducible."""
import numpy as np
import pytest

from rlanimate_addon.core import skeleton
from trainer.blender_io import rig_session
from trainer.paths import SAMPLE_RIG_BLEND, SAMPLE_RIG_FBX

bpy = pytest.importorskip("bpy")

MAX_FILE_BYTES = 1_000_000


@pytest.fixture
def scene():
    return rig_session.new_empty_scene()


def _load_blend(path):
    """Every object of the .blend at `path`, appended into the current scene."""
    with bpy.data.libraries.load(str(path), link=False) as (source, target):
        target.objects = list(source.objects)
    for obj in target.objects:
        bpy.context.scene.collection.objects.link(obj)
    return {obj.name: obj for obj in target.objects}


def _rest_errors(rig):
    """Largest head-position (m) and rest-frame errors of `rig`'s bones against the spec, in world space."""
    world = np.array(rig.matrix_world)
    position_error = frame_error = 0.0
    for bone in skeleton.BONES:
        rest = world @ np.array(rig.data.bones[skeleton.PREFIX + bone.name].matrix_local)
        position_error = max(position_error, np.abs(rest[:3, 3] - bone.head).max())
        frame_error = max(frame_error, np.abs(rest[:3, :3] - skeleton.rest_frame(bone)).max())
    return position_error, frame_error


def test_rig_has_every_bone_with_the_spec_geometry(scene):
    rig = _load_blend(SAMPLE_RIG_BLEND)[rig_session.SAMPLE_RIG_NAME]
    bones = rig.data.bones
    assert sorted(b.name for b in bones) == sorted(skeleton.PREFIX + b.name for b in skeleton.BONES)
    for spec in skeleton.BONES:
        bone = bones[skeleton.PREFIX + spec.name]
        expected_parent = None if spec.parent is None else skeleton.PREFIX + spec.parent
        assert (bone.parent.name if bone.parent else None) == expected_parent
        assert np.allclose(bone.tail_local, spec.tail, atol=1e-6)
        if spec.parent is not None:
            assert bone.use_connect == np.allclose(skeleton.BONE_BY_NAME[spec.parent].tail, spec.head)
    position_error, frame_error = _rest_errors(rig)
    assert position_error < 1e-6 and frame_error < 1e-5
    assert {pb.rotation_mode for pb in rig.pose.bones} == {"QUATERNION"}


def test_body_mesh_is_skinned_to_the_rig(scene):
    objects = _load_blend(SAMPLE_RIG_BLEND)
    rig = objects[rig_session.SAMPLE_RIG_NAME]
    body = next(o for o in objects.values() if o.type == "MESH")
    assert body.parent is rig
    assert [(m.type, m.object) for m in body.modifiers] == [("ARMATURE", rig)]
    group_names = {g.name for g in body.vertex_groups}
    assert group_names <= {b.name for b in rig.data.bones}
    some_bones = ("Head", "Hips", "LeftForeArm", "RightUpLeg", "LeftHandIndex2")
    assert {skeleton.PREFIX + b for b in some_bones} <= group_names
    weighted = [len(v.groups) for v in body.data.vertices]
    assert min(weighted) >= 1, "every vertex must follow a bone"
    # The body spans a standing adult: feet near the ground, top of the head near 1.8 m.
    z = np.array([v.co.z for v in body.data.vertices])
    assert z.min() < 0.05 and 1.7 < z.max() < 1.85


def test_fbx_reimports_every_bone_with_the_same_rest_pose(scene):
    before = set(bpy.data.objects)
    bpy.ops.import_scene.fbx(filepath=str(SAMPLE_RIG_FBX))
    imported = [o for o in bpy.data.objects if o not in before]
    rig = rig_session.find_armature(imported)
    assert sorted(b.name for b in rig.data.bones) == sorted(skeleton.PREFIX + b.name for b in skeleton.BONES)
    assert np.allclose(rig.matrix_world.to_scale(), 1.0, atol=1e-6), "re-import must be in metres"
    position_error, frame_error = _rest_errors(rig)
    assert position_error < 1e-4 and frame_error < 1e-3
    assert any(o.type == "MESH" for o in imported)


def test_committed_blend_is_readable_by_blender_4_2():
    """Blender 5.0's .blend header cannot be read by 4.2 LTS, so the committed file is saved by 4.2."""
    import zstandard  # a dependency of the bpy wheel; Blender compresses .blend files with zstd

    with open(SAMPLE_RIG_BLEND, "rb") as handle:
        header = zstandard.ZstdDecompressor().stream_reader(handle).read(12)
    # The pre-5.0 header: "BLENDER", pointer size "-" or "_", endianness "v" or "V", 3-digit version.
    assert header[:7] == b"BLENDER" and header[7:8] in b"-_" and header[8:9] in b"vV", header
    assert int(header[9:12]) <= 402, f"saved by Blender {header[9:12].decode()}, newer than 4.2"


def test_build_script_reproduces_the_committed_character(scene, tmp_path):
    from sample_rigs import build_character

    build_character.build(tmp_path)
    for name in ("character.blend", "character.fbx"):
        assert (tmp_path / name).stat().st_size < MAX_FILE_BYTES
        assert (SAMPLE_RIG_BLEND.parent / name).stat().st_size < MAX_FILE_BYTES

    def snapshot(path):
        rig_session.new_empty_scene()
        objects = _load_blend(path)
        rig = objects[rig_session.SAMPLE_RIG_NAME]
        body = next(o for o in objects.values() if o.type == "MESH")
        bones = [(b.name, tuple(np.round(np.array(b.matrix_local).ravel(), 6))) for b in rig.data.bones]
        verts = np.array([tuple(v.co) for v in body.data.vertices])
        faces = [tuple(p.vertices) for p in body.data.polygons]
        groups = [tuple((g.group, g.weight) for g in v.groups) for v in body.data.vertices]
        return bones, verts, faces, groups

    built, committed = snapshot(tmp_path / "character.blend"), snapshot(SAMPLE_RIG_BLEND)
    assert built[0] == committed[0]
    assert np.array_equal(built[1], committed[1])
    assert built[2:] == committed[2:]
