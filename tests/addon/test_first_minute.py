"""What an animator meets in the first minute: Start Frame at the playhead, a gesture past the scene's end, the
character's mesh selected, each behaviour's own length, and Bone Map from VRM File only where it applies."""
import bpy
import pytest

import addon_helpers as helpers
import real_rigs
from rlanimate_addon.blender import generate, gestures, preferences
from rlanimate_addon.core import frame_rate
from test_registration import _draw


def test_start_frame_follows_the_playhead_until_set(settings):
    rig = helpers.load_sample_rig()
    bpy.context.scene.frame_set(57)
    assert settings.start_frame == 57
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT", frame_count=60) == {"FINISHED"}
    assert gestures.placed_gestures(rig)[0].record["start"] == 57
    settings.start_frame = 140  # an explicit value wins over the playhead
    bpy.context.scene.frame_set(3)
    assert settings.start_frame == 140
    assert bpy.ops.rlanimate.select_gesture(gesture="") == {"FINISHED"}, "a new gesture starts at the playhead"
    assert settings.start_frame == 3


def test_a_gesture_past_the_scenes_end_is_baked_with_a_warning_and_the_end_can_be_extended(settings):
    helpers.load_sample_rig()
    scene = bpy.context.scene
    scene.frame_end = 100
    for key, value in dict(behaviour="WAVE", arm="LEFT", start_frame=60, frame_count=90).items():
        setattr(settings, key, value)
    summary = generate.generate(bpy.context, settings)
    assert "warning: frames 60-149 run past the scene's end, frame 100: click 'Extend Scene End'" in summary
    def offered():
        return any(c[0] == "operator" and c[1] == "rlanimate.extend_scene_end" for c in _draw(settings))

    assert offered()
    assert bpy.ops.rlanimate.extend_scene_end() == {"FINISHED"} and scene.frame_end == 149
    assert not offered(), "nothing runs past the end now"


@pytest.mark.parametrize("name", ["sample", "kenney", "ue_gltf"])
def test_selecting_the_characters_mesh_uses_the_armature_that_deforms_it(settings, tmp_path, name):
    rig = helpers.load_sample_rig() if name == "sample" else real_rigs.load_shared(name, tmp_path, still=True)
    mesh = next(o for o in bpy.data.objects if o.type == "MESH" and any(
        m.type == "ARMATURE" and m.object == rig for m in o.modifiers))
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj is mesh)
    helpers.activate(mesh)
    for key, value in dict(behaviour="WAVE", arm="RIGHT", start_frame=1, frame_count=80).items():
        setattr(settings, key, value)
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    assert [g.record["behaviour"] for g in gestures.placed_gestures(rig)] == ["WAVE"]
    assert any(c[0] == "operator" and c[1] == "rlanimate.select_gesture" for c in _draw(settings)), \
        "the panel lists the gestures of the mesh's armature"
    helpers.activate(helpers.add_empty("Empty", (0.0, 0.0, 0.0)))
    with pytest.raises(RuntimeError, match="nor a mesh an armature deforms"):
        bpy.ops.rlanimate.generate_gesture()


def test_each_behaviour_has_its_own_default_length_from_the_agent_file(settings):
    agent = preferences.selected_agent(bpy.context)
    fps = bpy.context.scene.render.fps / bpy.context.scene.render.fps_base
    lengths = {}
    for behaviour in agent.behaviours:
        settings.behaviour = behaviour
        lengths[behaviour] = settings.frame_count
        assert lengths[behaviour] == frame_rate.scene_frames(round(agent.average_frames[behaviour]), fps)
    assert len(set(lengths.values())) > 1, lengths
    settings.frame_count = 70  # set, it is the length of every behaviour
    settings.behaviour = "POINT"
    assert settings.frame_count == 70


def test_bone_map_from_vrm_file_shows_only_for_an_armature_from_a_vrm(settings, tmp_path):
    """Not on a character whose bones Generate maps; on one from a VRM file, and on one whose bones it cannot
    map (its refusal offers the VRM file's map first)."""
    rig = helpers.load_sample_rig()

    def offered():
        return any(c[0] == "operator" and c[1] == "rlanimate.bone_map_from_vrm" for c in _draw(settings))

    assert not offered(), "a Mixamo character is not a VRM"
    rig.rlanimate.vrm_file = str(tmp_path / "character.vrm")  # as the glTF import keeps it
    assert offered()
    rig.rlanimate.vrm_file = ""
    rig.data.bones[helpers.rig_bone(rig, "Neck")].name = "joint_07"  # a name no family knows
    assert offered()
