"""The rig session: an empty scene, loading rigs, finding the armature."""
import os
import sys

import pytest

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io import rig_session
from trainer.paths import SAMPLE_RIG_BLEND, SAMPLE_RIG_FBX

bpy = pytest.importorskip("bpy")


@pytest.fixture
def scene():
    return rig_session.new_empty_scene()


def test_new_empty_scene_is_empty():
    bpy.data.objects.new("leftover", None)
    scene = rig_session.new_empty_scene()
    assert len(scene.objects) == 0 and len(bpy.data.objects) == 0


@pytest.mark.parametrize("path", [SAMPLE_RIG_BLEND, SAMPLE_RIG_FBX])
def test_load_rig_brings_the_mesh_only_when_asked(scene, path):
    rig = rig_session.load_rig(path)
    assert rig.type == "ARMATURE" and rig.name in scene.objects
    assert rig_session.is_rig(rig)
    assert [o.type for o in scene.objects] == ["ARMATURE"]
    rig_session.new_empty_scene()
    rig_session.load_rig(path, with_mesh=True)
    assert sorted(o.type for o in bpy.context.scene.objects) == ["ARMATURE", "MESH"]


def test_find_armature_names_the_missing_bones(scene):
    rig = rig_session.load_rig()
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    for name in ("LeftEye", "RightHandIndex4"):
        rig.data.edit_bones.remove(rig.data.edit_bones[skeleton.PREFIX + name])
    bpy.ops.object.mode_set(mode="OBJECT")
    assert not rig_session.is_rig(rig)
    with pytest.raises(RLAnimateError, match="LeftEye, RightHandIndex4"):
        rig_session.find_armature([rig])
    with pytest.raises(RLAnimateError, match="No armature"):
        rig_session.find_armature([])


def test_load_rig_rejects_missing_and_unknown_files(scene, tmp_path):
    with pytest.raises(RLAnimateError, match="does not exist"):
        rig_session.load_rig(tmp_path / "nothing.blend")
    other = tmp_path / "rig.obj"
    other.write_text("# not a rig\n")
    with pytest.raises(RLAnimateError, match="neither .blend nor .fbx"):
        rig_session.load_rig(other)
    for name in ("broken.fbx", "broken.blend"):
        (tmp_path / name).write_bytes(b"not a rig")
        with pytest.raises(RLAnimateError, match=name):
            rig_session.load_rig(tmp_path / name)


def test_blender_output_holds_back_prints_but_not_the_terminal_stream(capfd):
    with rig_session.blender_output() as terminal:
        print("FBX version: 7400")
        os.write(1, b"C-level noise\n")
        terminal.write("progress\n")
        print("clip_import: a note", file=sys.stderr)
        sys.stderr.flush()
    print("after")
    out, err = capfd.readouterr()
    assert "FBX version" not in out + err and "noise" not in out + err
    assert "progress" in err and "a note" in err and "after" in out
    with rig_session.blender_output(verbose=True):
        print("FBX version: 7400")
    assert "FBX version: 7400" in capfd.readouterr().out
