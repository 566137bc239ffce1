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


def _gesture_keys(rig):
    """{(gesture, layer, data path, index): (K, 2) keys} of every F-curve of the armature's gestures."""
    keys = {}
    for placed in gestures.placed_gestures(rig):
        for name, layer in placed.layers.items():
            for fcurve in action_adapter.all_fcurves(layer.action):
                co = np.empty(2 * len(fcurve.keyframe_points), dtype=np.float32)
                fcurve.keyframe_points.foreach_get("co", co)
                keys[placed.record["id"], name, fcurve.data_path, fcurve.array_index] = co.reshape(-1, 2)
    return keys


def test_a_re_bake_the_bake_check_refuses_stops_following_with_a_note_and_a_report(settings, monkeypatch):
    """The target hung from the hand the gesture moves (issue 44: a ReferenceError in the handler, twice per
    update, and following never stopped): the refused bake is undone, following stops at once with a note the
    panel shows and a report, and later moves bake nothing."""
    rig, target = _point(settings)
    before = _gesture_keys(rig)
    time.sleep(follow_target.THROTTLE)
    target.parent, target.parent_type, target.parent_bone = rig, "BONE", helpers.rig_bone(rig, "LeftHand")
    bpy.context.view_layer.update()
    stopped = follow_target.note(rig)
    assert stopped.startswith("Follow Target stopped for 'RLAnimate Point Right': ")
    assert "moves with the gesture" in stopped
    assert follow_target.reports == [stopped]
    after = _gesture_keys(rig)
    assert after.keys() == before.keys() and all(np.array_equal(after[k], before[k]) for k in before)
    baked = []
    monkeypatch.setattr(follow_target.generate, "bake", lambda *args, **kwargs: baked.append(args))
    _move(target, NEW)
    _move(target, OLD)
    assert baked == [] and follow_target.note(rig) == stopped
    monkeypatch.undo()
    follow_target._flush_reports()
    assert follow_target.reports == []
    assert helpers.generate(rig, settings, target=helpers.add_empty("Elsewhere", NEW)) == {"FINISHED"}


def test_re_bakes_keep_the_names_the_animator_gave_the_actions(settings):
    """Issue 44: Follow Target renamed back an action the animator renamed. Neither it nor Generate Again does;
    a gesture Generate named takes the name of what it bakes."""
    rig, target = _point(settings)
    gesture = gestures.last_targeted(rig)
    gesture.action.name, gesture.torso.action.name = "Hello there", "Hello torso"
    _move(target, NEW)
    follow_target.settle()
    gesture = gestures.last_targeted(rig)
    assert (gesture.action.name, gesture.torso.action.name) == ("Hello there", "Hello torso")
    to_old, to_new = _apex_angles(rig)
    assert to_new <= MAX_APEX_ANGLE_DEG < to_old, "baked again all the same"
    assert helpers.generate(rig, settings, behaviour="WAVE", target=target) == {"FINISHED"}
    assert rig.rlanimate.gesture == "" and gestures.find(rig, "Hello there").record["behaviour"] == "WAVE"
    assert helpers.generate(rig, settings, behaviour="POINT", arm="LEFT", start_frame=200) == {"FINISHED"}
    left = next(g for g in gestures.placed_gestures(rig) if g.record["arm"] == "LEFT")
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT", start_frame=200) == {"FINISHED"}
    assert left.action.name == "RLAnimate Wave Left" and left.torso.action.name == "RLAnimate Wave Left (torso)"


def test_a_drag_reads_the_rig_once_and_the_resting_position_is_baked_as_generate_bakes_it(settings, monkeypatch):
    """While the target is dragged, each move bakes the gesture again over the pose underneath as the first move
    read it; once the target rests, the gesture is baked in full (the rig read again), and its keys are those
    Generate gives the same gesture at the final position (a twin rig, not dragged), bit for bit."""
    rig, target = _point(settings)
    helpers.load_sample_rig()
    twin = next(o for o in bpy.data.objects if o.type == "ARMATURE" and o is not rig)
    twin_target = helpers.add_empty("Twin target", OLD)
    settings.follow_target = False
    options = dict(behaviour="POINT", arm="RIGHT", start_frame=1, frame_count=100)
    assert helpers.generate(twin, settings, target=twin_target, **options) == {"FINISHED"}
    settings.follow_target, settings.target = True, target
    reads = []
    sample_rig = follow_target.generate.armature_io.sample_rig
    monkeypatch.setattr(follow_target.generate.armature_io, "sample_rig",
                        lambda *args, **kwargs: reads.append(1) or sample_rig(*args, **kwargs))
    for t in np.linspace(0.0, 1.0, 8):
        _move(target, tuple((1.0 - t) * np.array(OLD) + t * np.array(NEW)))
    assert len(reads) == 1, "read once for the whole drag"
    assert follow_target.settle() == [rig] and len(reads) == 2
    settings.follow_target = False
    twin_target.location = NEW
    assert helpers.generate(twin, settings, target=twin_target, **options) == {"FINISHED"}
    followed, generated = (_gesture_keys(r) for r in (rig, twin))
    assert generated.keys() == followed.keys()
    assert all(np.array_equal(generated[k], followed[k]) for k in followed)



def test_a_drag_too_slow_to_bake_again_moves_the_aim_alone_then_bakes_the_gesture_at_rest(settings, monkeypatch):
    """Where a preview of the whole gesture cannot keep up (KEEP_UP; forced here), the rest of the drag aims the
    gesture the drag baked last at the new position, the agent not run again: the finger follows all the same.
    At rest the agent runs again for the final position."""
    monkeypatch.setattr(follow_target, "KEEP_UP", 1e6)
    rig, target = _point(settings)
    runs = []
    blended = follow_target.generate.gesture.blended_gesture
    monkeypatch.setattr(follow_target.generate.gesture, "blended_gesture",
                        lambda *args: runs.append(1) or blended(*args))
    for t in np.linspace(0.25, 1.0, 4):
        _move(target, tuple((1.0 - t) * np.array(OLD) + t * np.array(NEW)))
    assert len(runs) == 1, "the agent ran for the first move only"
    to_old, to_new = _apex_angles(rig)
    assert to_new <= MAX_APEX_ANGLE_DEG < to_old, f"the aim does not follow: {to_new:.1f} deg off the new position"
    assert follow_target.settle() == [rig] and len(runs) == 2
    to_old, to_new = _apex_angles(rig)
    assert to_new <= MAX_APEX_ANGLE_DEG < to_old
