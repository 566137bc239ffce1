"""Generate's options on the sample character: editable keys, Replace and Combine layers over animation,
a bone of another armature as target, and a bone-map file saved, edited and loaded."""
import json

import bpy
import numpy as np
import pytest

import addon_helpers as helpers
from rlanimate_addon.blender import generate
from rlanimate_addon.core import key_reduction, rig_roles, skeleton
from test_generate import finger_angles, random_target
from test_rig_variants import _pose_snapshot


def _rotations(rig, bones, frames):
    """(F, B, 3, 3) local rotations (matrix_basis) of the bones at each frame."""
    snapshot = _pose_snapshot(rig, frames)
    return np.stack([snapshot[b][:, :3, :3] for b in bones], axis=1)


def test_editable_keys_play_the_gesture_within_the_tolerance_and_report_it(settings):
    rig = helpers.load_sample_rig()
    summaries, played = [], []
    for editable, start in ((False, 1), (True, 301)):
        settings.editable_keys, settings.key_tolerance = editable, 0.5
        for key, value in dict(behaviour="WAVE", arm="RIGHT", exaggeration=0.8, seed=0, start_frame=start,
                               frame_count=120).items():
            setattr(settings, key, value)
        helpers.activate(rig)
        summaries.append(generate.generate(bpy.context, settings))
        bones = [b.name for b in rig.pose.bones if not skeleton.strip_prefix(b.name).startswith(("Left", "Hips"))]
        played.append(_rotations(rig, bones, np.arange(start, start + 120)))
    error = key_reduction.angles_between(played[0], played[1])
    count = int(summaries[1].split("editable: ")[1].split(" ")[0])
    worst = float(summaries[1].split("worst deviation ")[1].split(" ")[0])
    print(f"editable keys: {count} keys (per-frame: {15 * 4 * 120}), worst {worst} deg, played {error.max():.3f} deg")
    assert error.max() <= 0.5 + 0.02 and worst <= 0.5
    assert count < 15 * 4 * 120 / 3  # a full-size wave at 0.8 needs about 2,000 of the 7,200 per-frame keys


def _idle(rig):
    """Hips swaying and the right arm hanging and swinging, keyed over frames 1-200."""
    hips, arm = (rig.pose.bones[helpers.rig_bone(rig, n)] for n in ("Hips", "RightArm"))
    for frame in range(1, 201, 10):
        sway = np.sin(frame / 15.0)
        hips.rotation_quaternion = (np.cos(0.04 * sway), 0.0, np.sin(0.04 * sway), 0.0)
        arm.rotation_quaternion = (np.cos(0.55), 0.0, 0.0, -np.sin(0.55 + 0.05 * sway))
        hips.keyframe_insert("rotation_quaternion", frame=frame)
        arm.keyframe_insert("rotation_quaternion", frame=frame)


@pytest.mark.parametrize("blend_type", ["REPLACE", "COMBINE"])
def test_replace_and_combine_layers_point_on_target_over_the_animation(settings, blend_type):
    rig = helpers.load_sample_rig()
    _idle(rig)
    location = random_target("RIGHT", np.random.default_rng(3))
    target = helpers.add_empty("Target", location)
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target, start_frame=40,
                            frame_count=120, blend_type=blend_type) == {"FINISHED"}
    strip = rig.animation_data.nla_tracks["RLAnimate Point Right"].strips[0]
    assert strip.blend_type == blend_type
    assert rig.animation_data.nla_tracks["RLAnimate Point Right (torso)"].strips[0].blend_type == "COMBINE"
    angles, bases = finger_angles(rig, "RIGHT", location, np.arange(40, 160))
    apex = int(np.argmax(np.linalg.norm(bases - bases[0], axis=1)))
    print(f"{blend_type}: apex miss {angles[apex]:.3f} deg")
    assert angles[apex] < 0.05


def test_pointing_at_a_bone_of_another_moving_character(settings):
    rig = helpers.load_sample_rig()
    other = helpers.build_rig("Other")
    other.location = (-1.0, -3.0, 0.2)
    other.keyframe_insert("location", frame=1)
    other.location = (1.5, -3.0, 0.2)
    other.keyframe_insert("location", frame=121)
    head = helpers.rig_bone(other, "Head")
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=other, target_bone=head,
                            start_frame=1, frame_count=120) == {"FINISHED"}
    misses = []
    for frame in range(31, 91, 10):
        bpy.context.scene.frame_set(frame)
        location = np.array(other.matrix_world @ other.pose.bones[head].head)
        misses.append(finger_angles(rig, "RIGHT", location, [frame])[0][0])
    assert max(misses) < 0.05, f"finger misses the moving head by {np.round(misses, 3)} deg"


def test_a_bone_map_file_is_saved_edited_and_loaded_for_a_rig_with_unknown_names(settings, tmp_path):
    rig = helpers.load_sample_rig()
    for bone in rig.data.bones:  # names no family knows
        bone.name = "bn_" + skeleton.strip_prefix(bone.name)[::-1]
    helpers.activate(rig)
    with pytest.raises(RuntimeError, match="has no bone for the roles Spine, Neck, Head"):
        bpy.ops.rlanimate.generate_gesture()
    path = tmp_path / "map.json"
    assert bpy.ops.rlanimate.save_bone_map(filepath=str(path)) == {"FINISHED"}
    data = json.loads(path.read_text())
    data["bones"] = {role: "bn_" + role[::-1] for role in rig_roles.ROLES}
    path.write_bytes(b"\xff\xfe not text")
    settings.bone_map_file = str(path)
    with pytest.raises(RuntimeError, match="is not UTF-8 text"):
        bpy.ops.rlanimate.generate_gesture()
    path.write_text(json.dumps(data))
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT") == {"FINISHED"}
    assert rig.animation_data.action is not None


def test_every_selected_armature_points_at_the_shared_target_or_none_is_touched(settings):
    first = helpers.load_sample_rig()
    second = helpers.build_rig("Second", prefix="mixamorig1:")
    second.location = (1.2, 0.4, 0.0)
    broken = helpers.build_rig("Broken", skip=("Neck",))
    broken.location = (-1.2, 0.4, 0.0)
    location = random_target("LEFT", np.random.default_rng(9))
    target = helpers.add_empty("Target", location)
    for key, value in dict(behaviour="POINT", arm="LEFT", target=target, start_frame=1, frame_count=100).items():
        setattr(settings, key, value)
    for obj in (first, second, broken, target):
        obj.select_set(True)
    helpers.activate(first)
    with pytest.raises(RuntimeError, match="'Broken' has no bone for the roles Neck"):
        bpy.ops.rlanimate.generate_gesture()
    assert all(o.animation_data is None or o.animation_data.action is None for o in (first, second))
    broken.select_set(False)
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    for rig in (first, second):
        angles, bases = finger_angles(rig, "LEFT", location, np.arange(1, 101))
        assert angles[int(np.argmax(np.linalg.norm(bases - bases[0], axis=1)))] < 0.05, rig.name


def test_eyes_aimed_by_their_own_constraints_are_left_to_them(settings):
    rig = helpers.load_sample_rig()
    left, right = helpers.rig_bone(rig, "LeftEye"), helpers.rig_bone(rig, "RightEye")
    track = rig.pose.bones[left].constraints.new("DAMPED_TRACK")
    track.target = helpers.add_empty("EyeTarget", (0.0, -3.0, 1.6))
    target = helpers.add_empty("Target", (-1.0, -2.5, 1.7))
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target) == {"FINISHED"}
    keyed = _gesture_bones_of(rig.animation_data.action)
    assert right in keyed and left not in keyed


def _gesture_bones_of(action):
    from test_rig_variants import _gesture_bones

    return _gesture_bones(action, None)


def test_an_armature_with_its_own_settings_gets_its_own_gesture_beside_the_shared_one(settings):
    shared = helpers.load_sample_rig()
    own = helpers.build_rig("Own", prefix="mixamorig1:")
    own.location = (1.5, 0.0, 0.0)
    location = random_target("RIGHT", np.random.default_rng(12))
    for key, value in dict(behaviour="POINT", arm="RIGHT", target=helpers.add_empty("Target", location),
                           start_frame=1, frame_count=100).items():
        setattr(settings, key, value)
    own.rlanimate.use_own_settings = True
    for key, value in dict(behaviour="WAVE", arm="LEFT", exaggeration=0.9, start_frame=11, frame_count=90).items():
        setattr(own.rlanimate.settings, key, value)
    for obj in (shared, own):
        obj.select_set(True)
    helpers.activate(shared)
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    assert shared.animation_data.action.name.startswith("RLAnimate Point Right")
    action = own.animation_data.action
    assert action.name.startswith("RLAnimate Wave Left") and tuple(action.frame_range) == (11.0, 100.0)
    angles, bases = finger_angles(shared, "RIGHT", location, np.arange(1, 101))
    assert angles[int(np.argmax(np.linalg.norm(bases - bases[0], axis=1)))] < 0.05
    helpers.activate(own)
    from rlanimate_addon.blender import properties

    assert properties.panel_settings(bpy.context) == own.rlanimate.settings, "the panel edits the armature's own"
