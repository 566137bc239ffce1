"""Generate Gesture on real rigs: pointing accuracy, wave size, return to start, other rigs, undo-safe errors."""
import math

import bpy
import numpy as np
import pytest

import addon_helpers as helpers
from rlanimate_addon.core import skeleton

RNG = np.random.default_rng()
MAX_APEX_ANGLE_DEG = 5.0


def random_target(arm, rng=RNG):
    """World position of an unseen target 1.5-4 m from the pointing shoulder, in the front hemisphere.

    Azimuth runs from 70 degrees out to the arm's side to 30 degrees across the body, elevation from
    -25 to +45 degrees, and the target is at least 0.3 m above the floor.
    """
    side = 1.0 if arm == "LEFT" else -1.0
    while True:
        azimuth = math.radians(rng.uniform(-30.0, 70.0)) * side  # + is towards the arm's side
        elevation = math.radians(rng.uniform(-25.0, 45.0))
        distance = rng.uniform(1.5, 4.0)
        direction = np.array([math.sin(azimuth) * math.cos(elevation), -math.cos(azimuth) * math.cos(elevation),
                              math.sin(elevation)])
        target = skeleton.shoulder_rest_position(arm) + distance * direction
        if target[2] >= 0.3:
            return target


def finger_angles(rig, arm, target, frames):
    """(F,) angle in degrees between the index finger and the line from its base to the target."""
    prefix = skeleton.ARM_PREFIX[arm]
    bones = [helpers.rig_bone(rig, prefix + "HandIndex1"), helpers.rig_bone(rig, prefix + "HandIndex4")]
    heads = helpers.bone_heads(rig, bones, frames)  # (F, 2, 3)
    finger = heads[:, 1] - heads[:, 0]
    to_target = np.asarray(target) - heads[:, 0]
    cos = np.sum(finger * to_target, axis=1) / np.linalg.norm(finger, axis=1) / np.linalg.norm(to_target, axis=1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))), heads[:, 0]


def apex(base_positions):
    """Index of the frame where the finger base is farthest from where it started (arms hanging)."""
    return int(np.argmax(np.linalg.norm(base_positions - base_positions[0], axis=1)))


@pytest.mark.parametrize("arm", ["LEFT", "RIGHT"])
def test_point_aims_the_index_finger_at_unseen_targets_and_returns(settings, arm):
    rig = helpers.load_sample_rig()
    helpers.stand_neutral(rig)
    for k in range(2):
        location = random_target(arm)
        target = helpers.add_empty(f"Target{k}", location)
        start = 1 + 200 * k
        assert helpers.generate(rig, settings, behaviour="POINT", arm=arm, target=target,
                                start_frame=start) == {"FINISHED"}
        frames = np.arange(start, start + settings.frame_count)
        angles, bases = finger_angles(rig, arm, location, frames)
        peak = apex(bases)
        assert angles[peak] <= MAX_APEX_ANGLE_DEG, (
            f"{arm} finger misses the target at {np.round(location, 2)} by {angles[peak]:.1f} deg at the apex")
        assert np.linalg.norm(bases[-1] - bases[0]) < 0.02, "the gesture must end where it started"


def test_exact_aim_holds_on_a_target_behind_the_character(settings):
    """The agent never learned to point behind itself and its hand does not come back from there; the
    aim still holds the finger on the target through the middle of the gesture."""
    rig = helpers.load_sample_rig()
    helpers.stand_neutral(rig)
    location = skeleton.shoulder_rest_position("RIGHT") + (0.0, 2.0, 0.0)  # the character faces -Y
    target = helpers.add_empty("Behind", location)
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target, start_frame=1) == {"FINISHED"}
    count = settings.frame_count
    angles, bases = finger_angles(rig, "RIGHT", location, np.arange(1, count + 1))
    middle = angles[int(0.4 * count):int(0.6 * count)]
    print(f"behind: middle of the gesture misses by {middle.max():.2f} deg at worst")
    assert middle.max() < 0.5 and np.linalg.norm(bases[-1] - bases[0]) < 0.02


@pytest.mark.parametrize("arm", ["LEFT", "RIGHT"])
def test_a_bigger_exaggeration_gives_a_wider_and_higher_wave(settings, arm):
    rig = helpers.load_sample_rig()
    helpers.stand_neutral(rig)
    hand = helpers.rig_bone(rig, skeleton.ARM_PREFIX[arm] + "Hand")
    sizes = []
    for k, exaggeration in enumerate((0.1, 0.9)):
        start = 1 + 300 * k
        assert helpers.generate(rig, settings, behaviour="WAVE", arm=arm, exaggeration=exaggeration,
                                start_frame=start) == {"FINISHED"}
        wrist = helpers.bone_heads(rig, [hand], np.arange(start, start + settings.frame_count))[:, 0]
        assert np.linalg.norm(wrist[-1] - wrist[0]) < 0.02, "the gesture must end where it started"
        raised = wrist[wrist[:, 2] > np.percentile(wrist[:, 2], 60)]  # the waving part, hand up
        sizes.append((np.ptp(raised[:, 0]), wrist[:, 2].max()))
    (width_small, height_small), (width_big, height_big) = sizes
    assert width_big > width_small, f"wave width {width_big:.3f} m should exceed {width_small:.3f} m"
    assert height_big > height_small, f"wave height {height_big:.3f} m should exceed {height_small:.3f} m"


def _animated_bones(rig, names):
    return [helpers.rig_bone(rig, n) for n in names]


@pytest.mark.parametrize("rig_kind", ["centimetres_y_up_rolled", "fbx_reimport_scaled"])
@pytest.mark.parametrize("behaviour", ["POINT", "WAVE"])
def test_other_rigs_move_as_the_sample_rig_does(settings, rig_kind, behaviour, tmp_path):
    """A rig in other units, axes and rolls gets the same world-space motion as the sample rig."""
    sample = helpers.load_sample_rig()
    if rig_kind == "centimetres_y_up_rolled":
        y_up = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
        other = helpers.build_rig("Other", units=100.0, axes=y_up, roll_to_x=True, prefix="mixamorig1:")
        scale = 1.0
    else:
        other = _reimport_sample_fbx(scale=0.01)
        scale = 0.01
    target = helpers.add_empty("Target", random_target("RIGHT"))
    values = dict(behaviour=behaviour, arm="RIGHT", target=target, exaggeration=0.7, seed=0)
    assert helpers.generate(sample, settings, **values) == {"FINISHED"}
    # The same target relative to the other rig: scale its offset from the origin with the rig.
    target.location = np.array(target.location) * scale
    assert helpers.generate(other, settings, **values) == {"FINISHED"}
    names = ["RightHand", "RightHandIndex1", "RightHandIndex4", "LeftHand", "Head"]
    frames = np.arange(1, settings.frame_count + 1)
    expected = helpers.bone_heads(sample, _animated_bones(sample, names), frames)
    got = helpers.bone_heads(other, _animated_bones(other, names), frames) / scale
    assert np.abs(got - expected).max() < 0.01, "world-space motion differs by more than 1 cm"


def _reimport_sample_fbx(scale):
    before = set(bpy.data.objects)
    bpy.ops.import_scene.fbx(filepath=str(helpers.SAMPLE_FBX),
                             global_scale=scale, automatic_bone_orientation=True)
    return next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")


def _pose_snapshot(rig, frames):
    every = [b.name for b in rig.pose.bones]
    return every, helpers.bone_heads(rig, every, frames)


def _fcurves(action):
    from rlanimate_addon.blender import action_adapter

    return action_adapter.ActionTarget(action, action.slots[0] if action_adapter.LAYERED else None).fcurves()


def _keys(action):
    return {(f.data_path, f.array_index): [tuple(p.co) for p in f.keyframe_points] for f in _fcurves(action)}


def _key_existing_animation(rig):
    """An action keying a leg and the right arm over frames 1-120, active on the rig; returns it."""
    arm, leg = rig.pose.bones[helpers.rig_bone(rig, "RightArm")], rig.pose.bones[helpers.rig_bone(rig, "LeftUpLeg")]
    for frame, angle in ((1, 0.0), (60, 0.6), (120, -0.3)):
        arm.rotation_quaternion = (math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0)
        leg.rotation_quaternion = (math.cos(angle / 2), math.sin(angle / 2), 0.0, 0.0)
        arm.keyframe_insert("rotation_quaternion", frame=frame)
        leg.keyframe_insert("rotation_quaternion", frame=frame)
    return rig.animation_data.action


def test_existing_animation_other_frames_and_other_actions_are_preserved(settings):
    rig = helpers.load_sample_rig()
    existing = _key_existing_animation(rig)
    other_action = bpy.data.actions.new("Unrelated")
    other_action.use_fake_user = True
    existing_keys = _keys(existing)
    outside = np.r_[1:40, 81:130]
    names, before_outside = _pose_snapshot(rig, outside)
    leg = [helpers.rig_bone(rig, "LeftUpLeg"), helpers.rig_bone(rig, "LeftFoot")]
    leg_before = helpers.bone_heads(rig, leg, np.arange(40, 81))

    result = helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT", start_frame=40, frame_count=41)
    assert result == {"FINISHED"}
    assert _keys(existing) == existing_keys, "keys of the existing action changed"
    assert len(other_action.fcurves if hasattr(other_action, "fcurves") else other_action.layers) == 0
    gesture = [a for a in bpy.data.actions if a.name.startswith("RLAnimate Wave Right")]
    assert [a.name for a in gesture] == ["RLAnimate Wave Right", "RLAnimate Wave Right (torso)"]
    strips = [s for t in rig.animation_data.nla_tracks for s in t.strips]
    assert {s.action for s in strips} == {existing, *gesture}
    _, after_outside = _pose_snapshot(rig, outside)
    assert np.abs(after_outside - before_outside).max() < 1e-5, "frames outside the gesture changed"
    assert np.abs(helpers.bone_heads(rig, leg, np.arange(40, 81)) - leg_before).max() < 1e-5, \
        "bones the gesture does not drive changed"
    # Inside its frames the gesture drives the arm, over the existing keys of the same bone.
    arm = helpers.rig_bone(rig, "RightArm")
    curves = sorted((f for f in _fcurves(gesture[0]) if f'"{arm}"' in f.data_path), key=lambda f: f.array_index)
    for frame in (40, 55, 70, 80):
        bpy.context.scene.frame_set(frame)
        keyed = [f.evaluate(frame) for f in curves]
        assert np.allclose(tuple(rig.pose.bones[arm].rotation_quaternion), keyed, atol=1e-5)

    # A second gesture stacks on top and leaves the first one alone.
    first_keys = _keys(gesture[0])
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT", start_frame=200) == {"FINISHED"}
    assert _keys(gesture[0]) == first_keys and _keys(existing) == existing_keys


@pytest.mark.parametrize("kind", ["sub-frame keys", "cycles loop", "manual frame range"])
def test_pushed_down_animation_plays_as_before_over_the_scene(settings, kind):
    rig = helpers.load_sample_rig()
    arm = rig.pose.bones[helpers.rig_bone(rig, "RightArm")]
    shift = 0.5 if kind == "sub-frame keys" else 0.0
    for frame, angle in ((1, 0.0), (60, 0.6), (120, -0.3)):
        arm.rotation_quaternion = (math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0)
        arm.keyframe_insert("rotation_quaternion", frame=frame + shift)
    existing = rig.animation_data.action
    if kind == "cycles loop":
        for fcurve in _fcurves(existing):
            fcurve.modifiers.new("CYCLES")
    if kind == "manual frame range":
        existing.use_frame_range, existing.frame_start, existing.frame_end = True, 30, 90
    scene = bpy.context.scene
    outside = np.r_[scene.frame_start:140, 181:scene.frame_end + 1]
    _, before = _pose_snapshot(rig, outside)
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT", start_frame=140, frame_count=41) == {
        "FINISHED"
    }
    _, after = _pose_snapshot(rig, outside)
    assert np.abs(after - before).max() < 1e-5, f"{kind}: the pushed-down action plays differently"


def _state(rig):
    """What a failed Generate must leave as it was."""
    data = rig.animation_data
    return (sorted(a.name for a in bpy.data.actions), bpy.context.scene.frame_current,
            None if data is None else (data.action, len(data.nla_tracks),
                                       [(d.data_path, d.driver.expression) for d in data.drivers]),
            [tuple(pb.rotation_quaternion) for pb in rig.pose.bones],
            [(c.name, c.influence, c.mute) for pb in rig.pose.bones for c in pb.constraints])


def _assert_refused(rig, message, **options):
    before = _state(rig)
    with pytest.raises(RuntimeError, match=message) as refusal:
        bpy.ops.rlanimate.generate_gesture(**options)
    assert "Traceback" not in str(refusal.value)
    assert _state(rig) == before


def test_every_bad_input_is_refused_with_its_message_and_changes_nothing(settings, tmp_path):
    rig = helpers.load_sample_rig()
    _key_existing_animation(rig)
    bpy.context.scene.frame_set(17)
    target = helpers.add_empty("Target", (1.0, -2.0, 1.5))

    helpers.activate(target)
    _assert_refused(rig, "not an armature")

    helpers.activate(rig)
    settings.behaviour, settings.target, settings.use_cursor = "POINT", None, False
    _assert_refused(rig, "needs a target")

    settings.target = target
    settings.frame_count = 0
    _assert_refused(rig, "at least 3 frames")
    settings.frame_count = 1
    _assert_refused(rig, "at least 3 frames")
    settings.frame_count = 2  # the first and last frames are the start pose: nothing would move
    _assert_refused(rig, "2 frames long: it starts and ends at the pose of its start frame, so nothing would move")
    settings.frame_count = 50

    for start in (1_048_574 - 48, 2_000_000_000, -1_048_575):  # past the last frame; keys collapsing
        settings.start_frame = start
        _assert_refused(rig, rf"Frames {start}-{start + 49} leave Blender's frame range \(-1048574 to 1048574\)")
    settings.start_frame = 1_048_574 - 49
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}, "the last frames Blender has are allowed"
    settings.start_frame = 1

    target.location = (float("nan"), -2.0, 1.5)
    _assert_refused(rig, r"target's position is not a number \(NaN or infinite\) on 50 of the gesture's 50 frames")
    target.location = (1.0, -2.0, 1.5)

    damaged = tmp_path / "damaged.npz"
    damaged.write_bytes(b"PK\x03\x04 truncated")
    helpers.addon_preferences().agent_path = str(damaged)
    _assert_refused(rig, "damaged.npz")
    helpers.addon_preferences().agent_path = str(tmp_path / "missing.npz")
    _assert_refused(rig, "does not exist")
    helpers.addon_preferences().agent_path = ""

    partial = helpers.build_rig("Partial", skip=("LeftHandIndex4", "LeftHandIndex3", "Neck", "Head"))
    helpers.activate(partial)
    _assert_refused(partial, r"roles Neck, Head \(closest bone naming: Mixamo\)")
    helpers.activate(rig)
    data = rig.animation_data  # the animation is on the NLA now, under the gestures baked above
    track = data.nla_tracks[0]
    track.is_solo = True
    _assert_refused(rig, f"The NLA track {track.name!r} of 'RLAnimate_Character' is soloed")
    track.is_solo = False
    track.strips[0].select = True
    data.use_tweak_mode = True  # Tab on the strip in the NLA editor
    _assert_refused(rig, "'RLAnimate_Character' is in NLA tweak mode")
    data.use_tweak_mode = False
    hand = rig.data.bones[helpers.rig_bone(rig, "RightHand")]
    hand.use_inherit_rotation = False
    _assert_refused(rig, f"Bone {hand.name!r} of 'RLAnimate_Character' does not inherit its parent's rotation")
    hand.use_inherit_rotation = True
    settings.target_bone = "NoSuchBone"
    settings.target = partial
    _assert_refused(rig, "The target 'Partial' has no bone 'NoSuchBone'")
    settings.target = target  # an object target: the Target Bone left from an armature target is unused
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}, "the panel hides Target Bone for an object"
    settings.target_bone = ""

    helpers.activate(rig)
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}, "valid settings must work after refusals"


def test_cursor_fallback_and_an_animated_target_is_tracked(settings):
    rig = helpers.load_sample_rig()
    bpy.context.scene.cursor.location = (-1.5, -2.5, 1.2)
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=None,
                            use_cursor=True) == {"FINISHED"}
    target = helpers.add_empty("Moving", (-2.0, -2.0, 1.0))
    target.keyframe_insert("location", frame=300)
    target.location = (1.0, -2.0, 2.0)
    target.keyframe_insert("location", frame=360)
    bpy.context.scene.frame_set(5)
    assert helpers.generate(rig, settings, target=target, start_frame=300, frame_count=61) == {"FINISHED"}
    assert bpy.context.scene.frame_current == 5, "the scene frame must be restored"


@pytest.mark.parametrize("arm", ["LEFT", "RIGHT"])
def test_exact_aim_off_bakes_the_agents_own_aim(settings, arm):
    """Exact Aim on: the finger passes through the target. Off: the baked finger points where the
    agent alone points (its raw rollout through the numpy FK), and only the pointing Arm bone differs."""
    from rlanimate_addon.blender import preferences
    from rlanimate_addon.core import aim, behaviour_metrics, gesture

    rig = helpers.load_sample_rig()
    helpers.stand_neutral(rig)
    location = random_target(arm, np.random.default_rng(21 if arm == "LEFT" else 22))
    target = helpers.add_empty("Target", location)
    count = settings.frame_count
    runs = {}
    for exact in (True, False):  # each on the still rig: the first one deleted (its keys only) before the second
        if not exact:
            assert bpy.ops.rlanimate.delete_gesture(gesture=rig.animation_data.action.name) == {"FINISHED"}
            assert rig.animation_data.action is None and not rig.animation_data.nla_tracks
        assert helpers.generate(rig, settings, behaviour="POINT", arm=arm, target=target, start_frame=1,
                                exact_aim=exact) == {"FINISHED"}
        frames = np.arange(1, 1 + count)
        runs[exact] = finger_angles(rig, arm, location, frames)[0], helpers.bone_heads(
            rig, [b.name for b in rig.pose.bones], frames)
    agent = preferences.load_agent(preferences.BUNDLED_AGENT)
    objectives = gesture.build_objectives(agent.space, "POINT", arm, count, targets=np.tile(location, (count, 1)),
                                          rest_heads=gesture.canonical_rig().rest_heads)
    _, base, finger, _ = aim.finger_lines(gesture.run_agent(agent, "POINT", objectives), arm)
    raw = behaviour_metrics.pointing_angles(base, finger, location)
    full = gesture.blend_weights(count) >= 1.0  # frames that show the agent's pose unblended
    np.testing.assert_allclose(runs[False][0][full], raw[full], atol=0.5)
    assert runs[True][0][apex(base)] <= MAX_APEX_ANGLE_DEG
    names = [b.name for b in rig.pose.bones]
    arm_chain = {helpers.rig_bone(rig, skeleton.ARM_PREFIX[arm] + b) for b in ("Arm", "ForeArm", "Hand")}
    others = [k for k, n in enumerate(names) if n not in arm_chain and not skeleton.strip_prefix(n).startswith(
        skeleton.ARM_PREFIX[arm] + "Hand")]
    np.testing.assert_allclose(runs[True][1][:, others], runs[False][1][:, others], atol=1e-6)


def test_a_linked_armature_is_refused_and_a_library_override_keeps_its_gesture(settings, tmp_path):
    """A gesture on linked data would vanish on save; on a library override it survives a reopen."""
    helpers.load_sample_rig()
    library = tmp_path / "character.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(library))
    settings = helpers.enable_addon()
    with bpy.data.libraries.load(str(library), link=True) as (_, linked):
        linked.objects = [helpers.SAMPLE_RIG]
    rig = linked.objects[0]
    bpy.context.scene.collection.objects.link(rig)
    helpers.activate(rig)
    settings.behaviour = "WAVE"
    _assert_refused(rig, r"is linked from .*character\.blend, so a gesture baked onto it would be lost when the "
                         r"file is saved\. Make a library override")
    assert rig.animation_data is None

    override = rig.override_create(remap_local_usages=True)
    helpers.activate(override)
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    scene_file = tmp_path / "shot.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(scene_file))
    bpy.ops.wm.open_mainfile(filepath=str(scene_file))
    reopened = next(o for o in bpy.data.objects if o.override_library is not None)
    assert reopened.animation_data.action.name.startswith("RLAnimate Wave Right"), "the gesture was kept"
