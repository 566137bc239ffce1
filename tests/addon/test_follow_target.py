"""Follow Target: moving the target of the last Point gesture re-bakes it from the depsgraph update
(headless: move, then view_layer.update()), unless its keys were edited by hand."""
import time

import bpy
import numpy as np
import pytest

import addon_helpers as helpers
from rlanimate_addon.blender import action_adapter, follow_target, gestures
from test_constraints import _ik_rig
from test_generate import MAX_APEX_ANGLE_DEG, apex, finger_angles

OLD, NEW = (-1.2, -2.5, 1.7), (0.8, -2.8, 0.9)


def _point(settings):
    rig = helpers.load_sample_rig()
    target = helpers.add_empty("Target", OLD)
    settings.follow_target = True
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target, start_frame=1,
                            frame_count=100) == {"FINISHED"}
    return rig, target


def _move(target, location):
    """Move the target as a drag does, after the throttle's interval, and let the depsgraph update."""
    time.sleep(follow_target.THROTTLE)
    target.location = location
    bpy.context.view_layer.update()


def _apex_angles(rig):
    """Finger angles (degrees) at the apex of the pointing arm, to the old and the new position."""
    frames = np.arange(1, 101)
    to_old, bases = finger_angles(rig, "RIGHT", OLD, frames)
    to_new, _ = finger_angles(rig, "RIGHT", NEW, frames)
    peak = apex(bases)
    return to_old[peak], to_new[peak]


def test_moving_the_target_re_bakes_the_point_at_the_new_position(settings):
    rig, target = _point(settings)
    to_old, to_new = _apex_angles(rig)
    assert to_old <= MAX_APEX_ANGLE_DEG < to_new
    _move(target, NEW)
    to_old, to_new = _apex_angles(rig)
    assert to_new <= MAX_APEX_ANGLE_DEG < to_old, f"the arm does not follow: {to_new:.1f} deg off the new position"
    assert len([a for a in bpy.data.actions if gestures.RECORD in a]) == 1, "re-baked in place"
    settings.follow_target = False
    _move(target, OLD)
    to_old, to_new = _apex_angles(rig)
    assert to_new <= MAX_APEX_ANGLE_DEG < to_old, "with Follow Target off the gesture stays"


def test_a_gesture_edited_by_hand_is_never_re_baked(settings):
    rig, target = _point(settings)
    assert not gestures.edited(gestures.last_targeted(rig)), "the keys as written read back as written"
    action = rig.animation_data.action
    fcurve = action_adapter.all_fcurves(action)[0]
    fcurve.keyframe_points[10].co.y += 0.1  # the animator's own edit
    edited = fcurve.keyframe_points[10].co.y
    _move(target, NEW)
    assert fcurve.keyframe_points[10].co.y == edited
    assert "edited by hand" in follow_target.note(rig)
    to_old, _ = _apex_angles(rig)
    assert to_old <= MAX_APEX_ANGLE_DEG, "the edited gesture still points where it did"
    bone = fcurve.data_path.split('"')[1]
    with pytest.raises(RuntimeError, match=rf"The keys of 'RLAnimate Point Right' were edited by hand on {bone} "
                                           r"\(frame 11\).*'Replace Edited Keys'"):
        helpers.generate(rig, settings)
    assert fcurve.keyframe_points[10].co.y == edited, "Generate refuses to overwrite the edit"
    assert helpers.generate(rig, settings, replace_edited_keys=True) == {"FINISHED"}
    assert follow_target.note(rig) == "", "Generate again follows again"


def test_the_handler_comes_and_goes_with_the_add_on(settings):
    handlers = bpy.app.handlers.depsgraph_update_post
    assert [h for h in handlers if h.__name__ == "_on_update"] == [follow_target._on_update]
    helpers.disable_addon()
    assert follow_target._on_update not in handlers
    helpers.enable_addon()
    assert handlers.count(follow_target._on_update) == 1


def test_moving_a_handle_of_editable_keys_is_an_edit(settings):
    rig = helpers.load_sample_rig()
    target = helpers.add_empty("Target", OLD)
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target, editable_keys=True) \
        == {"FINISHED"}
    gesture = gestures.last_targeted(rig)
    assert not gestures.edited(gesture)
    point = next(p for f in action_adapter.all_fcurves(gesture.action) for p in f.keyframe_points
                 if p.interpolation == "BEZIER")
    point.handle_right.y += 0.05
    assert gestures.edited(gesture)


def test_a_re_bake_records_its_settings_and_follows_again(settings):
    rig, target = _point(settings)
    _move(target, NEW)
    record = gestures.last_targeted(rig).record
    assert record["note"] == "" and record["settings"]["target"] == target
    assert np.allclose(
        np.reshape(record["aimed_at"], (-1, 3))[0], np.array(rig.matrix_world.inverted() @ target.location)
    )
    _move(target, OLD)
    to_old, to_new = _apex_angles(rig)
    assert to_old <= MAX_APEX_ANGLE_DEG < to_new, "a second move is followed too"


def test_a_gesture_baked_muting_constraints_follows_muting_them_again(settings):
    rig, _, ik = _ik_rig()
    target = helpers.add_empty("Target", OLD)
    settings.follow_target = True
    settings.behaviour, settings.arm, settings.target, settings.start_frame, settings.frame_count = \
        "POINT", "RIGHT", target, 1, 100
    helpers.activate(rig)
    assert bpy.ops.rlanimate.generate_gesture(mute_constraints=True) == {"FINISHED"}
    _move(target, NEW)
    gesture = gestures.last_targeted(rig)
    assert gesture.record["note"] == "", gesture.record["note"]
    to_old, to_new = _apex_angles(rig)
    assert to_new <= MAX_APEX_ANGLE_DEG < to_old, f"the arm does not follow: {to_new:.1f} deg off the new position"
    assert len([a for a in bpy.data.actions if gestures.RECORD in a]) == 1, "re-baked in place"
    bpy.context.scene.frame_set(150)
    assert ik.influence == pytest.approx(0.7), "outside the gesture the constraint works as before"
