"""An animator's session, not one click: gestures on both arms, in sequence, over the animator's own keys,
baked again, deleted and undone, on the sample character and on real rigs made by others (../shared/rigs),
measured on the bones the mesh deforms with, as Blender plays them (tests/addon/real_rigs.py)."""
import bpy
import numpy as np
import pytest

import addon_helpers as helpers
import real_rigs
from rlanimate_addon.blender import action_adapter, gestures
from rlanimate_addon.core import gesture

#: The sample character and two real rigs made by others: a Mixamo-named one and an Unreal mannequin.
RIGS = ["sample", "kenney", "ue_gltf"]
#: Frames at which the animator's keys are checked, across every gesture of the sessions and beyond.
CHECKED = (1, 20, 40, 50, 65, 90, 120, 133, 150, 180, 230, 300)


def _load(name, folder):
    """The rig, still (no animation), active."""
    return helpers.load_sample_rig() if name == "sample" else real_rigs.load_shared(name, folder, still=True)


def _target(rig, settings, arm, seed):
    return real_rigs.world_target(rig, settings, arm, np.random.default_rng(seed))


def _generate(rig, settings, **values):
    """Generate Gesture as the panel's button runs it, one undo step (the operator's own)."""
    for key, value in values.items():
        setattr(settings, key, value)
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj is rig)
    helpers.activate(rig)
    return bpy.ops.rlanimate.generate_gesture("EXEC_DEFAULT", True)


def _point(rig, settings, arm, start, seed, **values):
    target = _target(rig, settings, arm, seed)
    empty = helpers.add_empty(f"Target {arm} {start}", tuple(target))
    assert _generate(rig, settings, behaviour="POINT", arm=arm, target=empty, start_frame=start, frame_count=93,
                     seed=0, **values) == {"FINISHED"}
    return target


def _wave(rig, settings, arm, start, **values):
    assert _generate(rig, settings, behaviour="WAVE", arm=arm, exaggeration=0.8, start_frame=start, frame_count=93,
                     seed=0, **values) == {"FINISHED"}


def _key_legs_and_hips(rig, settings):
    """The animator keys the hips (rotation and location) and a leg over frames 1-150; Blender puts the keys
    in the active action. Returns {(data path, index): (K, 2) keys} of the curves keyed."""
    roles = real_rigs.roles(rig, settings)
    hips = rig.pose.bones[roles["Hips"]]
    leg = next(rig.pose.bones[c.name] for c in hips.bone.children if c.name not in roles.values())
    for k, frame in enumerate((1, 40, 90, 150)):
        sway = 0.08 * np.sin(1.3 * k + 0.5)
        hips.rotation_quaternion = (np.cos(sway), 0.0, np.sin(sway), 0.0)
        hips.location = (0.02 * np.sin(k), 0.0, 0.01 * k)
        leg.rotation_quaternion = (np.cos(0.3 * sway), np.sin(0.3 * sway), 0.0, 0.0)
        for bone, paths in ((hips, ("rotation_quaternion", "location")), (leg, ("rotation_quaternion",))):
            for path in paths:
                bone.keyframe_insert(path, frame=frame)
    for bone in (hips, leg):
        bone.rotation_quaternion, bone.location = (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return {(f.data_path, f.array_index): _co(f) for f in _their_curves(rig, (hips.name, leg.name))}


def _co(fcurve):
    co = np.empty(2 * len(fcurve.keyframe_points), dtype=np.float32)
    fcurve.keyframe_points.foreach_get("co", co)
    return co.reshape(-1, 2)


def _their_curves(rig, bones):
    """The F-curves of the armature's actions (active, NLA strips) on the named bones' channels."""
    data = rig.animation_data
    targets = action_adapter.strip_targets(rig) + [t for t in [action_adapter.active_target(rig)] if t is not None]
    return [f for t in targets for f in t.fcurves() if any(f'"{b}"' in f.data_path for b in bones)] if data else []


def _assert_theirs_play_as_keyed(rig, keys):
    """The animator's keys are all there, unmoved, each in one curve, and the bones play them (within 1e-4)."""
    bones = {path.split('"')[1] for path, _ in keys}
    curves = {}
    for fcurve in _their_curves(rig, bones):
        assert (fcurve.data_path, fcurve.array_index) not in curves, "one curve per channel"
        curves[fcurve.data_path, fcurve.array_index] = fcurve
    assert curves.keys() == keys.keys(), "every curve of theirs is there"
    for channel, co in keys.items():
        assert np.array_equal(_co(curves[channel]), co), f"{channel} keys moved"
    for frame in CHECKED:
        bpy.context.scene.frame_set(frame)
        for (path, index), fcurve in curves.items():
            bone, prop = path.split('"')[1], path.rsplit(".", 1)[1]
            played = getattr(rig.pose.bones[bone], prop)[index]
            assert abs(played - fcurve.evaluate(frame)) < 1e-4, (path, index, frame)


def _keys_of_every_action():
    """{action name: {(data path, index): keys}} and the NLA tracks of every armature: to compare after undo."""
    keys = {a.name: {(f.data_path, f.array_index): _co(f).tolist() for f in action_adapter.all_fcurves(a)}
            for a in bpy.data.actions}
    tracks = {o.name: [(t.name, [(s.name, s.frame_start, s.frame_end, s.blend_out) for s in t.strips])
                       for t in o.animation_data.nla_tracks]
              for o in bpy.data.objects if o.type == "ARMATURE" and o.animation_data}
    return keys, tracks


def _wrist(rig, settings, arm, first, last):
    """(F, 3) the deformed wrist over frames first-last, and the arm's length."""
    joints, length = real_rigs.played_joints(rig, settings, arm, first, last - first + 1)
    return joints[:, 0], length


def _largest_step(path):
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).max())


@pytest.mark.parametrize("name", RIGS)
def test_an_animators_session_loses_nothing_of_theirs(settings, tmp_path, name):
    """Point right; the animator keys the hips and a leg (into the point's action, the active one); the point
    baked again; a wave on the left arm over it; a wave on the right taking over from the point; a point right
    after each wave; the third of the five baked again, and undone: every key of theirs is there and plays as
    keyed throughout, the handover keeps the point's frames and does not jump, and undo puts everything back."""
    rig = _load(name, tmp_path)
    right = _point(rig, settings, "RIGHT", 1, 1)
    theirs = _key_legs_and_hips(rig, settings)
    assert all(gestures.RECORD in f.id_data for f in _their_curves(rig, {p.split('"')[1] for p, _ in theirs})), \
        "Blender keyed them into the point's action"
    assert _generate(rig, settings, seed=1) == {"FINISHED"}, "the point baked again (same arm and start)"
    _assert_theirs_play_as_keyed(rig, theirs)
    assert real_rigs.point_miss(rig, settings, "RIGHT", right, 1, 93)[0] <= 1.0
    _wave(rig, settings, "LEFT", 40)
    _assert_theirs_play_as_keyed(rig, theirs)
    # The handover: a wave on the right arm from frame 50, while the point plays.
    alone, length = _wrist(rig, settings, "RIGHT", 1, 93)
    _wave(rig, settings, "RIGHT", 50)
    both, _ = _wrist(rig, settings, "RIGHT", 1, 142)
    ramp = gesture.blend_ramp(93)
    kept = np.linalg.norm(both[:45] - alone[:45], axis=1).max()
    own = max(_largest_step(alone), _largest_step(both[49 + ramp:142 - ramp]))  # the wave's, at full weight
    around = _largest_step(both[39:50 + ramp])  # frames 40 to the end of the wave's blend in
    print(f"{name}: handover keeps the point's frames 1-45 within {1000 * kept:.2f} mm; largest step around it "
          f"{around / length:.3f} arm lengths, the gestures' own {own / length:.3f}")
    assert kept <= 1e-3 and around <= 1.2 * own
    assert real_rigs.wave_strokes(rig, settings, "RIGHT", 50, 93)[0] >= 4
    # Points right after each wave start where the wave ended.
    _point(rig, settings, "LEFT", 133, 2)
    _point(rig, settings, "RIGHT", 143, 3)
    for arm, end in (("LEFT", 132), ("RIGHT", 142)):
        seam, _ = _wrist(rig, settings, arm, end - 1, end + 2)
        assert np.linalg.norm(seam[2] - seam[1]) <= 0.002 * length + np.linalg.norm(seam[1] - seam[0]), (arm, seam)
    _assert_theirs_play_as_keyed(rig, theirs)
    placed = gestures.in_timeline_order(rig)
    assert [(g.record["behaviour"], g.record["arm"], g.record["start"]) for g in placed] == [
        ("POINT", "RIGHT", 1), ("WAVE", "LEFT", 40), ("WAVE", "RIGHT", 50), ("POINT", "LEFT", 133),
        ("POINT", "RIGHT", 143)]
    # The third of five, selected in the list and baked again with another seed; then undone.
    before = _keys_of_every_action()
    bpy.ops.ed.undo_push(message="before the third is baked again")
    assert bpy.ops.rlanimate.select_gesture(gesture=placed[2].name) == {"FINISHED"}
    assert (settings.behaviour, settings.arm, settings.start_frame) == ("WAVE", "RIGHT", 50)
    settings.seed = 5
    assert bpy.ops.rlanimate.generate_gesture("EXEC_DEFAULT", True) == {"FINISHED"}
    assert _keys_of_every_action() != before
    _assert_theirs_play_as_keyed(rig, theirs)
    assert real_rigs.wave_strokes(rig, settings, "RIGHT", 50, 93)[0] >= 4
    rig_name = rig.name
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert _keys_of_every_action() == before, "one undo puts every key and track back"
    _assert_theirs_play_as_keyed(bpy.data.objects[rig_name], theirs)


def _gesture_named(rig, prefix):
    return next(g.name for g in gestures.placed_gestures(rig) if g.name.startswith(prefix))


@pytest.mark.parametrize("first", ["POINT", "WAVE"])
@pytest.mark.parametrize("name", RIGS)
def test_two_arms_play_together_as_each_played_alone_in_either_order(settings, tmp_path, name, first):
    """A Point with the right arm (frames 1-93) and a Wave with the left (20-112: at full weight over the
    point's hold), in either order: over its hold the finger stays within 1 degree of where it pointed alone,
    frame by frame (the point not aimed again over the wave's turn of the spine, it moved 4.3-4.6 degrees),
    the wave keeps the strokes it makes alone (each measured alone with the other one deleted, then put back
    by undo), and either can be baked again: the point then hits within 3 degrees and the wave makes at least
    4 strokes."""
    rig = _load(name, tmp_path)
    rig_name = rig.name
    make = {"POINT": lambda: _point(rig, settings, "RIGHT", 1, 4), "WAVE": lambda: _wave(rig, settings, "LEFT", 20)}
    target = make[first]()
    second = make["WAVE" if first == "POINT" else "POINT"]()
    target = target if first == "POINT" else second

    def finger(rig, settings):
        return real_rigs.finger_angles(rig, settings, "RIGHT", target, 1, 93)[:2]

    def strokes(rig, settings):
        return real_rigs.wave_strokes(rig, settings, "LEFT", 20, 93)[0]

    together = finger(rig, settings), strokes(rig, settings)
    alone = []
    for deleted, measure in (("RLAnimate Wave Left", finger), ("RLAnimate Point Right", strokes)):
        bpy.ops.ed.undo_push(message="before deleting")
        assert bpy.ops.rlanimate.delete_gesture("EXEC_DEFAULT", True, gesture=deleted) == {"FINISHED"}
        alone.append(measure(bpy.data.objects[rig_name], bpy.context.scene.rlanimate))
        assert bpy.ops.ed.undo() == {"FINISHED"}
    rig, settings = bpy.data.objects[rig_name], bpy.context.scene.rlanimate
    (angles, (hold_first, hold_last)), (angles_alone, _) = together[0], alone[0]
    moved = np.abs(angles - angles_alone)[hold_first:hold_last + 1].max()
    print(f"{name}, {first} first: over its hold the finger moved at most {moved:.3f} deg from where it pointed "
          f"alone; {together[1]} strokes (alone {alone[1]})")
    assert moved <= 1.0 and together[1] == alone[1] >= 4
    for prefix in ("RLAnimate Point Right", "RLAnimate Wave Left"):
        assert bpy.ops.rlanimate.select_gesture(gesture=_gesture_named(rig, prefix)) == {"FINISHED"}
        assert _generate(rig, settings, seed=2) == {"FINISHED"}
        assert real_rigs.point_miss(rig, settings, "RIGHT", target, 1, 93)[0] <= 3.0
        assert strokes(rig, settings) >= 4


def test_keys_edited_by_hand_are_not_overwritten_silently(settings):
    """Generate over a gesture whose own keys were edited refuses, naming the bones and frames, and changes
    nothing; with Replace Edited Keys it bakes. A key the animator put on a bone the gesture does not own is
    not an edit of it, and stays. The panel's list marks the edited gesture."""
    from rlanimate_addon.blender import generate

    rig = helpers.load_sample_rig()
    _point(rig, settings, "RIGHT", 1, 5)
    forearm = rig.pose.bones[helpers.rig_bone(rig, "RightForeArm")]
    action = rig.animation_data.action
    curve = next(f for f in action_adapter.all_fcurves(action) if f'"{forearm.name}"' in f.data_path)
    for point in curve.keyframe_points[39:41]:  # frames 40 and 41
        point.co.y += 0.05
    leg = rig.pose.bones[helpers.rig_bone(rig, "LeftUpLeg")]
    leg.rotation_quaternion = (0.99, 0.1, 0.0, 0.0)
    leg.keyframe_insert("rotation_quaternion", frame=30)
    before = _keys_of_every_action()
    placed = gestures.find(rig, action.name)
    assert list(gestures.edited(placed).values()) == [[40, 41]] and gestures.edited_lately(placed)
    labels = [c for c in _draw_calls() if c[0] == "operator" and c[1] == "rlanimate.select_gesture"]
    assert any("edited by hand" in c[2].get("text", "") for c in labels)
    with pytest.raises(RuntimeError, match=rf"The keys of 'RLAnimate Point Right' were edited by hand on "
                                           rf"{forearm.name} \(frames 40-41\), and Generate would bake it again.*"
                                           r"'Replace Edited Keys'"):
        _generate(rig, settings, seed=1)
    assert _keys_of_every_action() == before
    settings.replace_edited_keys = True
    summary = generate.generate(bpy.context, settings)
    assert "replaced the previous gesture" in summary and not gestures.edited(gestures.find(rig, action.name))
    leg_curves = [f for f in action_adapter.all_fcurves(action) if f'"{leg.name}"' in f.data_path]
    assert len(leg_curves) == 4 and leg_curves[0].keyframe_points[0].co.x == 30.0, "the animator's key stays"


def _draw_calls():
    from test_registration import _draw

    return _draw(bpy.context.scene.rlanimate)


def test_the_panel_lists_the_gestures_and_one_selected_is_baked_again_in_place(settings):
    """The list shows each gesture (behaviour, arm, frames, seed, target) in timeline order; selecting one loads
    its settings into the panel and Generate then bakes that one again in place, on its own track; the delete
    button removes its keys only; the report says where two gestures share the spine."""
    from rlanimate_addon.blender import generate

    rig = helpers.load_sample_rig()
    _point(rig, settings, "LEFT", 200, 6)
    _wave(rig, settings, "LEFT", 40)
    settings.seed = 0
    target = helpers.add_empty("Door", (-1.5, -2.0, 1.6))
    for key, value in dict(behaviour="POINT", arm="RIGHT", target=target, start_frame=1, frame_count=93).items():
        setattr(settings, key, value)
    helpers.activate(rig)
    summary = generate.generate(bpy.context, settings)
    assert "its spine, neck and head turns add to those of 'RLAnimate Wave Left' over frames 40-93" in summary
    rows = [c[2]["text"] for c in _draw_calls() if c[0] == "operator" and c[1] == "rlanimate.select_gesture"]
    assert rows == ["Point Right 1-93, seed 0, at Door", "Wave Left 40-132, seed 0",
                    "Point Left 200-292, seed 0, at Target LEFT 200"], rows
    tracks = [t.name for t in rig.animation_data.nla_tracks]
    others = {name: keys for name, keys in _keys_of_every_action()[0].items() if "Wave" not in name}
    assert bpy.ops.rlanimate.select_gesture(gesture="RLAnimate Wave Left") == {"FINISHED"}
    assert (settings.behaviour, settings.arm, settings.start_frame, settings.frame_count) == ("WAVE", "LEFT", 40, 93)
    labels = [c[2].get("text") for c in _draw_calls() if c[0] == "operator"]
    assert "Generate Again: RLAnimate Wave Left" in labels
    settings.seed, settings.exaggeration = 4, 0.5
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    assert [t.name for t in rig.animation_data.nla_tracks] == tracks, "in place, on its own tracks"
    record = gestures.find(rig, "RLAnimate Wave Left").record
    assert (record["settings"]["seed"], record["start"]) == (4, 40)
    after = _keys_of_every_action()[0]
    assert {name: after[name] for name in others if "Point Left" in name} == \
        {name: others[name] for name in others if "Point Left" in name}, "a gesture elsewhere is untouched"
    assert bpy.ops.rlanimate.delete_gesture(gesture="RLAnimate Wave Left") == {"FINISHED"}
    assert [g.name for g in gestures.in_timeline_order(rig)] == ["RLAnimate Point Right", "RLAnimate Point Left"]
    assert not [a for a in bpy.data.actions if a.name.startswith("RLAnimate Wave Left")]
    assert bpy.ops.rlanimate.select_gesture(gesture="") == {"FINISHED"} and rig.rlanimate.gesture == ""
