"""Rigs and settings Generate cannot serve well: a zero-scale armature or bone is refused naming it and the fix,
a bone-map file that is not one is refused before it is read whole, an armature in Edit mode is refused naming
the fix, and a gesture far below the agent's supported length is baked with a warning. A refusal changes
nothing."""
import bpy
import pytest

import addon_helpers as helpers
from rlanimate_addon.blender import generate, preferences
from rlanimate_addon.core import gesture


def _state(rig):
    """What a refused Generate must leave as it was."""
    return (sorted(a.name for a in bpy.data.actions), bpy.context.scene.frame_current, tuple(rig.scale),
            [(tuple(pb.rotation_quaternion), tuple(pb.scale)) for pb in rig.pose.bones])


def _assert_refused(rig, message):
    before = _state(rig)
    with pytest.raises(RuntimeError, match=message) as refusal:
        bpy.ops.rlanimate.generate_gesture()
    assert "Traceback" not in str(refusal.value) and "Singular" not in str(refusal.value)
    assert _state(rig) == before


@pytest.mark.parametrize("behaviour", ["POINT", "WAVE"])
@pytest.mark.parametrize("where", ["RightArm", "RightShoulder", "object", "object_x"])
def test_a_zero_scale_armature_or_bone_is_refused_naming_it_and_the_fix(settings, behaviour, where):
    rig = helpers.load_sample_rig()
    settings.behaviour, settings.arm = behaviour, "RIGHT"
    settings.target = helpers.add_empty("Target", (-1.2, -2.0, 1.7))
    helpers.activate(rig)
    if where.startswith("object"):  # was a traceback: "Matrix.invert(ed): matrix does not have an inverse"
        rig.scale = (0.0, 1.0, 1.0) if where == "object_x" else (0.0, 0.0, 0.0)
        message = (r"The armature object 'RLAnimate_Character' has zero scale on some axis .* set its scale "
                   r"\(Object Mode, N panel > Item > Scale, or Alt\+S for 1\) to non-zero values")
    else:  # was "LinAlgError: Singular matrix" for a point, and a wave "Baked" on a collapsed arm
        bone = helpers.rig_bone(rig, where)
        rig.pose.bones[bone].scale = (0.0, 0.0, 0.0)
        message = (rf"Bones of 'RLAnimate_Character' are scaled to zero \('{bone}' \(0.0, 0.0, 0.0\)\).* set their "
                   r"scale to 1 in Pose Mode \(Pose > Clear Transform > Scale, or Alt\+S\)")
    bpy.context.view_layer.update()
    _assert_refused(rig, message)


@pytest.mark.parametrize("source", ["/dev/zero", "two_megabytes.json"])
def test_a_bone_map_file_far_larger_than_a_bone_map_is_refused_unread(settings, tmp_path, source):
    rig = helpers.load_sample_rig()
    if source == "two_megabytes.json":
        source = tmp_path / source
        source.write_text('{"family": "x", "bones": {}}' + " " * (2 << 20))
    settings.behaviour, settings.bone_map_file = "WAVE", str(source)  # /dev/zero: a MemoryError after 4.9 GB
    helpers.activate(rig)
    if source == "/dev/zero":  # not a regular file: refused before a byte is read
        _assert_refused(rig, r"Cannot read the bone-map file '/dev/zero' \(it is a character device, not a regular "
                             r"file\): pick a bone-map JSON file saved from the panel, or clear the Bone Map field")
        return
    _assert_refused(rig, rf"The bone-map file '{source}' is larger than 1024 KB, so it is not a bone map: pick a "
                         "bone-map JSON file saved from the panel, or clear the Bone Map field")


def test_a_gesture_far_below_the_supported_length_is_baked_with_a_warning(settings):
    rig = helpers.load_sample_rig()
    helpers.activate(rig)
    settings.behaviour, settings.arm, settings.frame_count = "WAVE", "LEFT", 3
    shortest, longest = gesture.supported_length_range(preferences.selected_agent(bpy.context).average_frames["WAVE"])
    summary = generate.generate(bpy.context, settings)
    assert summary.startswith("Baked Wave Left") and "frames 1-3" in summary
    assert (f"(warning: 3 frames is below the agent's supported {shortest}-{longest}, so the gesture is rushed; set "
            f"Frames to {shortest} or more)") in summary
    settings.frame_count, settings.start_frame = shortest, 10
    assert "warning" not in generate.generate(bpy.context, settings)


def test_an_armature_in_edit_mode_is_refused_naming_the_fix_and_stays_in_edit_mode(settings):
    """Generate in Edit mode failed the bake check with bone-map advice (the pose does not play there): it is
    refused before anything is written, naming the fix."""
    rig = helpers.activate(helpers.load_sample_rig())
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj is rig)
    settings.behaviour, settings.arm = "WAVE", "LEFT"
    bpy.ops.object.mode_set(mode="EDIT")
    _assert_refused(rig, r"^Error: Armature 'RLAnimate_Character' is in Edit mode, where its pose does not play: leave "
                         r"Edit mode \(Tab, or choose Pose Mode\) and generate again.")
    assert rig.mode == "EDIT" and bpy.context.mode == "EDIT_ARMATURE"
    bpy.ops.object.mode_set(mode="POSE")
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"} and rig.animation_data.action is not None
