"""Frames Generate plays through Blender (blender/playback.py) evaluate the armature, not the meshes it deforms,
each frame once, and leave every modifier as it was, even when the bake is refused."""
import math

import bpy
import pytest

import addon_helpers as helpers
import real_rigs

OLD = (-1.2, -2.5, 1.7)


def _sway(rig, role):
    """An idle turn of one bone, keyed every 10 frames over 1-130: the rig is animated."""
    bone = rig.pose.bones[helpers.rig_bone(rig, role)]
    for frame in range(1, 131, 10):
        bone.rotation_quaternion = (math.cos(0.05 * frame), math.sin(0.05 * frame) * 0.1, 0.0, 0.0)
        bone.keyframe_insert("rotation_quaternion", frame=frame)
    bone.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)


def _generate_watched(rig, settings, **values):
    """[(frame, {mesh: each modifier's show_viewport})] of every frame Blender plays during a Generate that must
    finish."""
    played = []

    def handler(scene, *_):
        played.append((scene.frame_current, {o.name: [m.show_viewport for m in o.modifiers]
                                             for o in scene.objects if o.type == "MESH"}))
    bpy.app.handlers.frame_change_post.append(handler)
    try:
        assert helpers.generate(rig, settings, start_frame=1, **values) == {"FINISHED"}
    finally:
        bpy.app.handlers.frame_change_post.remove(handler)
    return played


def _blender_plays_the_pose(rig):
    """A Limit Rotation on the hips: Generate then reads the pose underneath through Blender, frame by frame."""
    limit = rig.pose.bones[helpers.rig_bone(rig, "Hips")].constraints.new("LIMIT_ROTATION")
    limit.use_limit_x, limit.max_x = True, 1.0


def test_frames_played_for_the_pose_underneath_leave_the_meshes_unevaluated_and_their_modifiers_as_they_were(
        settings):
    rig = helpers.load_sample_rig()
    body = next(o for o in bpy.data.objects if o.type == "MESH")
    subdivision = body.modifiers.new("Subdivision", "SUBSURF")
    subdivision.show_viewport = False  # the animator's: stays off
    _sway(rig, "Spine")
    _blender_plays_the_pose(rig)
    played = _generate_watched(rig, settings, behaviour="POINT", arm="RIGHT", target=helpers.add_empty("T", OLD),
                               frame_count=60)
    frames = [frame for frame, _ in played]
    assert set(range(1, 61)) <= set(frames), "the pose underneath read through Blender, frame by frame"
    assert len(frames) <= 60 + 3 + 2, "each frame once, the bake check's three, and the scene's frame put back"
    assert all(shown[body.name] == [False, False] for _, shown in played)
    assert [m.show_viewport for m in body.modifiers] == [True, False]


def test_a_refused_bake_puts_every_modifier_back(settings):
    rig = helpers.load_sample_rig()
    body = next(o for o in bpy.data.objects if o.type == "MESH")
    _sway(rig, "Spine")
    _blender_plays_the_pose(rig)
    with pytest.raises(RuntimeError, match="moves with the gesture"):
        helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=rig,
                         target_bone=helpers.rig_bone(rig, "LeftHand"), start_frame=1, frame_count=60)
    assert [m.show_viewport for m in body.modifiers] == [True]


def test_a_mesh_the_rig_follows_keeps_its_modifiers(settings):
    """A bone constraint reading another mesh (a Child Of its vertex group): that mesh is evaluated whole."""
    rig = helpers.load_sample_rig()
    body = next(o for o in bpy.data.objects if o.type == "MESH")
    bpy.ops.mesh.primitive_cube_add(location=(0.0, 1.0, 1.0))
    prop = bpy.context.active_object
    prop.modifiers.new("Bevel", "BEVEL")
    child_of = rig.pose.bones[helpers.rig_bone(rig, "LeftToeBase")].constraints.new("CHILD_OF")
    child_of.target = prop
    _sway(rig, "Spine")
    _blender_plays_the_pose(rig)
    played = _generate_watched(rig, settings, behaviour="WAVE", arm="RIGHT", frame_count=40)
    assert played and all(shown[prop.name] == [True] and shown[body.name] == [False] for _, shown in played)


def test_a_rigify_arm_in_ik_is_read_in_the_same_pass_as_the_pose_underneath(settings):
    """The ORG- bones an arm in IK plays are read on the frames played for the pose underneath (they were played
    a second time before)."""
    rig = real_rigs.rigify_rig("IK")
    torso = rig.pose.bones["torso"]
    for frame in range(1, 61, 10):
        torso.rotation_quaternion = (math.cos(0.01 * frame), 0.0, 0.0, math.sin(0.01 * frame))
        torso.keyframe_insert("rotation_quaternion", frame=frame)
    played = _generate_watched(rig, settings, behaviour="WAVE", arm="RIGHT", frame_count=40)
    frames = [frame for frame, _ in played]
    assert set(range(1, 41)) <= set(frames) and len(frames) <= 40 + 3 + 2
