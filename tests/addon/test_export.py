"""Export FBX: Blender's exporter writes the rig, its mesh and the baked gesture, and they read back."""
import os

import bpy
import numpy as np
import pytest

import addon_helpers as helpers
from rlanimate_addon.blender import export
from rlanimate_addon.core import skeleton


def _imported(path):
    """Objects read from the FBX by Blender's importer with its defaults, as an animator imports a file
    (anim_offset=1: the take's time 0 lands on frame 1)."""
    before = set(bpy.data.objects)
    bpy.ops.import_scene.fbx(filepath=str(path))
    return [o for o in bpy.data.objects if o not in before]


def _key_own_animation(rig):
    """An idle of the character's own under the gestures: the spine sways from frame 1 to 90."""
    spine = rig.pose.bones[helpers.rig_bone(rig, "Spine")]
    for frame, angle in ((1, -0.1), (30, 0.1), (60, -0.1), (90, 0.1)):
        spine.rotation_quaternion = (np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2))
        spine.keyframe_insert("rotation_quaternion", frame=frame)


def test_fbx_round_trip_reproduces_every_joint_within_a_millimetre(settings, tmp_path):
    """With the importer's defaults, frame for frame: it came back one frame late (8-13 cm at the right hand)."""
    rig = helpers.load_sample_rig()
    _key_own_animation(rig)
    target = helpers.add_empty("Target", (-1.2, -2.0, 1.7))
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target, start_frame=1,
                            frame_count=40) == {"FINISHED"}
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT", start_frame=30,
                            frame_count=50) == {"FINISHED"}
    bpy.context.scene.frame_end = 20  # the export must still take in every baked frame
    helpers.add_empty("Selected", (0, 0, 0)).select_set(True)
    selected = {o.name for o in bpy.context.view_layer.objects if o.select_get()}
    path = tmp_path / "gesture.fbx"
    assert bpy.ops.rlanimate.export_fbx(filepath=str(path)) == {"FINISHED"}
    assert bpy.context.scene.frame_end == 20, "the scene's frame range must be restored"
    assert {o.name for o in bpy.context.view_layer.objects if o.select_get()} == selected

    imported = _imported(path)
    assert sorted(o.type for o in imported) == ["ARMATURE", "MESH"], "armature and mesh, nothing else"
    copy = next(o for o in imported if o.type == "ARMATURE")
    assert sorted(b.name for b in copy.data.bones) == sorted(b.name for b in rig.data.bones), "no leaf bones"
    assert copy.animation_data.action.frame_range[0] == 1.0, "the take starts at time 0: frame 1, not 2"
    frames = np.arange(1, 91)
    names = [skeleton.PREFIX + b.name for b in skeleton.BONES]
    baked = helpers.bone_heads(rig, names, frames)
    read_back = helpers.bone_heads(copy, names, frames)
    assert np.ptp(baked[:, :, 2], axis=0).max() > 0.1, "the gesture should move the hands"
    error = np.linalg.norm(read_back - baked, axis=2)  # (frames, joints), metres
    assert error.max() < 1e-3, f"{error.max() * 1e3:.2f} mm on frame {frames[error.max(axis=1).argmax()]}"


@pytest.mark.parametrize("scene_start, gesture_start", [(1, -20), (50, 60)], ids=["gesture_from_-20", "scene_from_50"])
def test_every_keyed_frame_plays_at_its_own_time_whatever_the_scenes_start(settings, tmp_path, scene_start,
                                                                          gesture_start):
    """A gesture from frame -20 (frames -20..0 were lost and the rest played a frame late) and a scene starting
    at frame 50 (its take played 49 frames early) come back on their own frames with the importer's defaults."""
    rig = helpers.load_sample_rig()
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT", start_frame=gesture_start,
                            frame_count=50) == {"FINISHED"}
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = scene_start, scene_start + 60
    scene.frame_set(7)
    summary = export.export_rig(bpy.context, str(tmp_path / "take.fbx"))
    first = min(scene_start, gesture_start)
    assert f"frames {first}-{scene_start + 60} each at its own time" in summary
    assert (scene.frame_start, scene.frame_current) == (scene_start, 7), "the scene's range and frame are kept"
    copy = next(o for o in _imported(tmp_path / "take.fbx") if o.type == "ARMATURE")
    assert tuple(copy.animation_data.action.frame_range) == (first, scene_start + 60)
    frames = np.arange(gesture_start, gesture_start + 50)
    names = [skeleton.PREFIX + b.name for b in skeleton.BONES]
    baked, read_back = helpers.bone_heads(rig, names, frames), helpers.bone_heads(copy, names, frames)
    assert np.ptp(baked[:, :, 2], axis=0).max() > 0.1, "the wave should move the hand"
    error = np.linalg.norm(read_back - baked, axis=2)
    assert error.max() < 1e-3, f"{error.max() * 1e3:.2f} mm on frame {frames[error.max(axis=1).argmax()]}"


def test_export_refuses_without_an_armature(settings, tmp_path):
    helpers.activate(helpers.add_empty("NotARig", (0, 0, 0)))
    with pytest.raises(RuntimeError, match="not an armature"):
        bpy.ops.rlanimate.export_fbx(filepath=str(tmp_path / "x.fbx"))
    assert not (tmp_path / "x.fbx").exists()


@pytest.mark.parametrize("where, message", [
    ("missing_folder/x.fbx", r"The folder .*missing_folder does not exist: choose an existing folder\."),
    ("", r"is a folder: give a file name ending in \.fbx\."),
    ("a_file.txt/x.fbx", r"The folder .*a_file\.txt does not exist"),
])
def test_export_to_a_bad_path_is_one_clear_message(settings, tmp_path, where, message):
    helpers.load_sample_rig()
    (tmp_path / "a_file.txt").write_text("not a folder")
    before = sorted(p.name for p in tmp_path.iterdir())
    with pytest.raises(RuntimeError, match=message) as refusal:
        bpy.ops.rlanimate.export_fbx(filepath=str(tmp_path / where))
    assert "Traceback" not in str(refusal.value) and len(str(refusal.value).splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert bpy.context.scene.frame_end == 250


@pytest.mark.skipif(not os.access("/proc", os.W_OK), reason="needs a writable-looking /proc (Linux, as root)")
def test_an_export_the_fbx_writer_fails_on_is_one_line_with_its_reason(settings):
    helpers.load_sample_rig()
    with pytest.raises(RuntimeError, match=r"Could not write /proc/rlanimate\.fbx: FileNotFoundError: \[Errno 2\]") \
            as refusal:
        bpy.ops.rlanimate.export_fbx(filepath="/proc/rlanimate.fbx")
    assert "Traceback" not in str(refusal.value) and len(str(refusal.value).splitlines()) == 1
