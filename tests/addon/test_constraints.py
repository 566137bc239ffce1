"""Constraints that would override the gesture: refused by name, or muted over the gesture's frames only."""
import bpy
import numpy as np
import pytest

import addon_helpers as helpers
from rlanimate_addon.core import gesture
from test_generate import _assert_refused, _fcurves, _key_existing_animation, _state

START, COUNT = 40, 41


def _ik_rig():
    """The sample rig with an IK constraint (influence 0.7) on the right forearm towards an empty."""
    rig = helpers.load_sample_rig()
    forearm = rig.pose.bones[helpers.rig_bone(rig, "RightForeArm")]
    ik = forearm.constraints.new("IK")
    ik.target, ik.chain_count, ik.influence = helpers.add_empty("IK Target", (-0.8, -0.5, 1.0)), 2, 0.7
    return helpers.activate(rig), forearm, ik


def test_a_constraint_overriding_the_arm_is_refused_by_name_and_changes_nothing(settings):
    rig, forearm, _ = _ik_rig()
    settings.behaviour, settings.start_frame, settings.frame_count = "WAVE", START, COUNT
    _assert_refused(
        rig,
        rf"Constraint 'IK' \(Inverse Kinematics, target IK Target\) on {forearm.name} overrides the rotations the "
        rf"gesture keys, so the bake would not play\. Click 'Generate, Muting Constraints'",
    )


def test_muting_keeps_the_constraint_outside_the_gesture_and_lets_the_gesture_play_inside(settings):
    rig, forearm, ik = _ik_rig()
    _key_existing_animation(rig)  # the gesture goes on an NLA strip, with no effect outside its frames
    hand = helpers.rig_bone(rig, "RightHand")
    outside = [1, START - 1, START + COUNT, 200]
    before = helpers.bone_heads(rig, [forearm.name, hand], outside)
    settings.behaviour, settings.start_frame, settings.frame_count = "WAVE", START, COUNT
    assert bpy.ops.rlanimate.generate_gesture(mute_constraints=True) == {"FINISHED"}
    after = helpers.bone_heads(rig, [forearm.name, hand], outside)
    assert np.abs(after - before).max() < 1e-5, "outside the gesture the constraint acts as before"
    keyed = next(a for a in bpy.data.actions if a.name.startswith("RLAnimate Wave Right"))
    curves = sorted((f for f in _fcurves(keyed) if f'"{forearm.name}"' in f.data_path), key=lambda f: f.array_index)
    full = START + np.flatnonzero(gesture.blend_weights(COUNT) == 1.0)  # frames the gesture shows unblended
    for frame in (full[0], full[len(full) // 2], full[-1]):
        bpy.context.scene.frame_set(int(frame))
        assert ik.influence == 0.0
        # The forearm's evaluated rotation (constraints included) is the keyed one.
        evaluated = (forearm.parent.matrix.inverted() @ forearm.matrix).to_quaternion()
        rest = (forearm.parent.bone.matrix_local.inverted() @ forearm.bone.matrix_local).to_quaternion()
        keyed_rotation = rest @ type(rest)([f.evaluate(frame) for f in curves])
        assert abs(evaluated.dot(keyed_rotation)) == pytest.approx(1.0, abs=1e-5)
    for frame in outside + [START, START + COUNT - 1]:
        bpy.context.scene.frame_set(frame)
        assert ik.influence == pytest.approx(0.7, abs=1e-6), "the influence fades, from and back to its own value"
    # The constraint fades out as the gesture blends in: the hand does not jump at either end (switched
    # off at once, it jumped by the 10 cm between the constraint's pose and the keyed one).
    for edge in (START - 1, START, START + COUNT - 2, START + COUNT - 1):
        step = np.linalg.norm(np.diff(helpers.bone_heads(rig, [hand], [edge, edge + 1])[:, 0], axis=0))
        assert step < 0.01, f"the hand jumps {step:.3f} m from frame {edge} to {edge + 1}"

    # A second gesture mutes it over its own frames as well, the first one's frames kept.
    settings.start_frame = 200
    assert bpy.ops.rlanimate.generate_gesture(mute_constraints=True) == {"FINISHED"}
    curve = rig.animation_data.drivers.find(ik.path_from_id("influence"))
    assert curve.driver.expression == "frame" and len(curve.keyframe_points) == 2 * COUNT
    for frame, value in ((START + COUNT // 2, 0.0), (120, 0.7), (220, 0.0), (250, 0.7)):
        bpy.context.scene.frame_set(frame)
        assert ik.influence == pytest.approx(value, abs=1e-6)


def test_a_constraint_with_an_animated_influence_is_not_overwritten(settings):
    rig, forearm, ik = _ik_rig()
    ik.keyframe_insert("influence", frame=1)
    settings.behaviour, settings.start_frame, settings.frame_count = "WAVE", START, COUNT
    before = _state(rig)
    _assert_refused(rig, "has an animated influence, which Generate will not overwrite", mute_constraints=True)
    assert _state(rig) == before


def test_muted_disabled_and_unrelated_constraints_are_left_alone(settings):
    rig, forearm, ik = _ik_rig()
    ik.mute = True
    leg = rig.pose.bones[helpers.rig_bone(rig, "LeftUpLeg")]
    leg.constraints.new("COPY_ROTATION").target = helpers.add_empty("Leg Target", (0, 0, 0))
    settings.behaviour, settings.start_frame, settings.frame_count = "WAVE", START, COUNT
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    assert not rig.animation_data.drivers



def test_generate_again_over_a_muted_constraint_fades_it_once_as_the_first_click_did(settings):
    """Regenerating replaces the gesture and its mute: the constraint's influence is faded by the new
    gesture's blend once, not by the old fade times the new one (0.7 (1 - w)^2 in the ramps)."""
    rig, _, ik = _ik_rig()
    settings.behaviour, settings.start_frame, settings.frame_count = "WAVE", START, COUNT
    path = ik.path_from_id("influence")

    def influence_keys():
        points = rig.animation_data.drivers.find(path).keyframe_points
        return np.array([tuple(p.co) for p in points])

    assert bpy.ops.rlanimate.generate_gesture(mute_constraints=True) == {"FINISHED"}
    first = influence_keys()
    ramp = START + np.flatnonzero((gesture.blend_weights(COUNT) > 0.2) & (gesture.blend_weights(COUNT) < 0.8))
    expected = 0.7 * (1.0 - gesture.blend_weights(COUNT))
    assert np.allclose(first[:, 1], expected, atol=1e-6) and len(ramp) > 2
    for _ in range(2):
        assert bpy.ops.rlanimate.generate_gesture(mute_constraints=True) == {"FINISHED"}
        assert np.array_equal(influence_keys(), first), "the fade of the replaced gesture is undone first"
    for frame in ramp[:3]:
        bpy.context.scene.frame_set(int(frame))
        assert ik.influence == pytest.approx(expected[frame - START], abs=1e-6)
    # The gesture selected in the panel's list, baked again at other frames, gives back the old frames' influence
    # and fades its own.
    assert bpy.ops.rlanimate.select_gesture(gesture="RLAnimate Wave Right") == {"FINISHED"}
    settings.start_frame = START + 10
    assert bpy.ops.rlanimate.generate_gesture(mute_constraints=True) == {"FINISHED"}
    assert len([a for a in bpy.data.actions if a.name.startswith("RLAnimate Wave Right")]) == 2, "main and torso"
    for frame, value in ((START + 2, 0.7), (START + 10 + COUNT // 2, 0.0), (START + 10 + COUNT - 1, 0.7)):
        bpy.context.scene.frame_set(frame)
        assert ik.influence == pytest.approx(value, abs=1e-6)
