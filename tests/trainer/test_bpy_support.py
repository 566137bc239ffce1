"""Headless-Blender helpers: arguments, loading rigs, finding the armature."""
import pytest

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer import bpy_support

bpy = pytest.importorskip("bpy")


@pytest.fixture
def scene():
    return bpy_support.new_empty_scene()


def test_script_args_under_blender_and_python():
    assert bpy_support.script_args(["blender", "-b", "-P", "x.py", "--", "--epochs", "3"]) == ["--epochs", "3"]
    assert bpy_support.script_args(["x.py", "--epochs", "3"]) == ["--epochs", "3"]


def test_new_empty_scene_is_empty():
    bpy.data.objects.new("leftover", None)
    scene = bpy_support.new_empty_scene()
    assert len(scene.objects) == 0 and len(bpy.data.objects) == 0


@pytest.mark.parametrize("path", [bpy_support.SAMPLE_RIG_BLEND, bpy_support.SAMPLE_RIG_FBX])
def test_load_rig_brings_the_mesh_only_when_asked(scene, path):
    rig = bpy_support.load_rig(path)
    assert rig.type == "ARMATURE" and rig.name in scene.objects
    assert bpy_support.is_rig(rig)
    assert [o.type for o in scene.objects] == ["ARMATURE"]
    bpy_support.new_empty_scene()
    bpy_support.load_rig(path, with_mesh=True)
    assert sorted(o.type for o in bpy.context.scene.objects) == ["ARMATURE", "MESH"]


def test_find_armature_names_the_missing_bones(scene):
    rig = bpy_support.load_rig()
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    for name in ("LeftEye", "RightHandIndex4"):
        rig.data.edit_bones.remove(rig.data.edit_bones[skeleton.PREFIX + name])
    bpy.ops.object.mode_set(mode="OBJECT")
    assert not bpy_support.is_rig(rig)
    with pytest.raises(RLAnimateError, match="LeftEye, RightHandIndex4"):
        bpy_support.find_armature([rig])
    with pytest.raises(RLAnimateError, match="No armature"):
        bpy_support.find_armature([])


def test_load_rig_rejects_missing_and_unknown_files(scene, tmp_path):
    with pytest.raises(RLAnimateError, match="does not exist"):
        bpy_support.load_rig(tmp_path / "nothing.blend")
    other = tmp_path / "rig.obj"
    other.write_text("# not a rig\n")
    with pytest.raises(RLAnimateError, match="neither .blend nor .fbx"):
        bpy_support.load_rig(other)
    for name in ("broken.fbx", "broken.blend"):
        (tmp_path / name).write_bytes(b"not a rig")
        with pytest.raises(RLAnimateError, match=name):
            bpy_support.load_rig(tmp_path / name)
