"""The pose underneath evaluated in numpy from keys (blender/pose_underneath.py) is Blender's own."""
import math

import bpy
import numpy as np

import addon_helpers as helpers
from rlanimate_addon.blender import action_adapter, pose_underneath

FRAMES = np.arange(-5, 160)


def _key_everything(rig):
    """Keys of every kind the numpy evaluation reads: Bezier quaternions (auto-clamped and free
    handles), linear XZY Euler angles, constant axis-angle, the hips' location and scale; active."""
    bones = {role: rig.pose.bones[helpers.rig_bone(rig, role)] for role in
             ("Hips", "Spine", "Spine1", "Neck", "RightArm", "RightForeArm", "LeftArm")}
    bones["Spine1"].rotation_mode, bones["Neck"].rotation_mode = "XZY", "AXIS_ANGLE"
    for frame in range(1, 131, 13):
        angle = 0.3 * math.sin(0.07 * frame)
        for role in ("Hips", "Spine", "RightArm", "RightForeArm", "LeftArm"):
            bones[role].rotation_quaternion = (math.cos(angle), math.sin(angle), 0.2 * angle, -0.1)
            bones[role].keyframe_insert("rotation_quaternion", frame=frame)
        bones["Spine1"].rotation_euler = (angle, -0.5 * angle, 2.0 * angle)
        bones["Spine1"].keyframe_insert("rotation_euler", frame=frame)
        bones["Neck"].rotation_axis_angle = (angle, 0.3, 1.0, 0.1)
        bones["Neck"].keyframe_insert("rotation_axis_angle", frame=frame)
        bones["Hips"].location = (0.05 * angle, 0.0, -0.1 * angle)
        bones["Hips"].scale = (1.0 + 0.1 * angle,) * 3
        bones["Hips"].keyframe_insert("location", frame=frame)
        bones["Hips"].keyframe_insert("scale", frame=frame)
    action = rig.animation_data.action
    for fcurve in action_adapter.all_fcurves(action):
        kind = fcurve.data_path.rsplit(".", 1)[1]
        for k, point in enumerate(fcurve.keyframe_points):
            point.interpolation = {"rotation_euler": "LINEAR", "rotation_axis_angle": "CONSTANT"}.get(kind, "BEZIER")
            if kind == "rotation_quaternion" and k % 3 == 1:  # a free handle reaching past the next key
                point.handle_right_type = "FREE"
                point.handle_right = (point.co[0] + 20.0, point.co[1] + 0.4)
        fcurve.update()
    return [b.name for b in bones.values()] + [helpers.rig_bone(rig, "RightHand")]


def _blender(rig, names, frames=FRAMES):
    basis, pose, values = [], [], {n: [] for n in names}
    for frame in frames:
        bpy.context.scene.frame_set(int(frame))
        basis.append([np.array(rig.pose.bones[n].matrix_basis) for n in names])
        pose.append([np.array(rig.pose.bones[n].matrix) for n in names])
        for n in names:
            pb = rig.pose.bones[n]
            path = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}.get(pb.rotation_mode,
                                                                                                 "rotation_euler")
            values[n].append(tuple(getattr(pb, path)))
    return np.array(basis), np.array(pose), {n: np.array(v) for n, v in values.items()}


def _assert_as_blender(rig, names, frames=FRAMES):
    evaluated = pose_underneath.sample(rig, names, frames)
    assert evaluated is not None, "evaluated in numpy"
    numpy_basis, numpy_pose, numpy_values = evaluated
    basis, pose, values = _blender(rig, names, frames)
    assert np.abs(numpy_basis - basis).max() < 2e-5
    assert np.abs(numpy_pose - pose).max() < 2e-5 * np.abs(pose).max()
    assert all(np.abs(numpy_values[n] - values[n]).max() < 2e-5 for n in names)


def test_keys_of_the_active_action_evaluate_as_blender_plays_them(settings):
    rig = helpers.load_sample_rig()
    _assert_as_blender(rig, _key_everything(rig))


def test_nla_strips_pushed_down_scaled_and_repeated_evaluate_as_blender_plays_them(settings):
    rig = helpers.load_sample_rig()
    names = _key_everything(rig)
    data = rig.animation_data
    action = data.action
    track = data.nla_tracks.new()
    strip = track.strips.new("Idle", 20, action)
    if hasattr(strip, "action_slot"):
        strip.action_slot = action.slots[0]
    strip.scale, strip.repeat, strip.extrapolation = 0.7, 1.5, "HOLD"
    data.action = None
    _assert_as_blender(rig, names)


def test_constraints_and_drivers_leave_the_pose_to_blender(settings):
    rig = helpers.load_sample_rig()
    names = _key_everything(rig)
    arm = rig.pose.bones[helpers.rig_bone(rig, "RightArm")]
    for kind, change in (("IK", {}), ("COPY_ROTATION", {"mix_mode": "ADD"}), ("COPY_LOCATION", {"use_offset": True}),
                         ("COPY_TRANSFORMS", {"owner_space": "LOCAL"})):
        constraint = arm.constraints.new(kind)
        constraint.target, constraint.subtarget = rig, helpers.rig_bone(rig, "Head")
        for name, value in change.items():
            setattr(constraint, name, value)
        assert pose_underneath.sample(rig, names, FRAMES) is None, kind
        arm.constraints.remove(constraint)
    assert pose_underneath.sample(rig, names, FRAMES) is not None
    rig.pose.bones[helpers.rig_bone(rig, "Head")].driver_add("location", 0)
    assert pose_underneath.sample(rig, names, FRAMES) is not None, "a driver on a bone outside the chain moves none"
    rig.pose.bones[helpers.rig_bone(rig, "Spine2")].driver_add("location", 0)
    assert pose_underneath.sample(rig, names, FRAMES) is None, "Spine2 carries the arms"
    rig.data.bones[helpers.rig_bone(rig, "RightShoulder")].inherit_scale = "AVERAGE"
    rig.animation_data.drivers.remove(rig.animation_data.drivers[-1])
    assert pose_underneath.sample(rig, names, FRAMES) is None, "only full inheritance is evaluated in numpy"


def test_the_layouts_generate_writes_evaluate_as_blender_plays_them(settings):
    """Gestures composed as Generate lays them out (blender/gestures.py): a still rig's first gesture (the active
    action, then a HOLD strip), Replace and Combine main strips, Combine torso strips, a handover's trimmed strips
    blended out; every bone of the rig."""
    rig = helpers.load_sample_rig()
    target = helpers.add_empty("Target", (-1.2, -2.5, 1.7))
    for values in (dict(behaviour="POINT", arm="RIGHT", target=target, start_frame=1, frame_count=93),
                   dict(behaviour="WAVE", arm="LEFT", start_frame=20, frame_count=93),
                   dict(behaviour="WAVE", arm="RIGHT", start_frame=50, frame_count=80),
                   dict(behaviour="POINT", arm="LEFT", target=target, start_frame=140, frame_count=60,
                        blend_type="COMBINE")):
        assert helpers.generate(rig, settings, **values) == {"FINISHED"}
    strips = [s for t in rig.animation_data.nla_tracks for s in t.strips]
    assert {s.blend_type for s in strips} == {"REPLACE", "COMBINE"} and any(s.blend_out > 0 for s in strips)
    _assert_as_blender(rig, [b.name for b in rig.pose.bones], np.arange(-5, 210))


def test_combined_blended_held_and_muted_strips_evaluate_as_blender_plays_them(settings):
    """Over an action held on the NLA: a Combine strip of Euler, quaternion, partial location and scale keys with
    blends in and out held forward, the same action as a Replace strip scaled and repeated, a muted Combine strip
    (its channels still start from their defaults there) and muted F-curves (which Blender does not evaluate),
    and the active action combined on top at 0.4 influence."""
    rig = helpers.load_sample_rig()
    names = _key_everything(rig)
    names.append(helpers.rig_bone(rig, "RightHand"))
    data = rig.animation_data
    base = action_adapter.active_target(rig)
    data.action = None
    layer = _layer_action(rig)
    tracks = [data.nla_tracks.new() for _ in range(3)]
    _strip(tracks[0], 1, base).extrapolation = "HOLD"
    combined = _strip(tracks[1], 30, layer)
    combined.blend_type, combined.blend_in, combined.blend_out = "COMBINE", 8, 12
    combined.extrapolation = "HOLD_FORWARD"
    repeated = _strip(tracks[1], 100, layer)
    repeated.scale, repeated.repeat, repeated.blend_in, repeated.extrapolation = 1.5, 2, 5, "NOTHING"
    muted = _strip(tracks[2], 60, layer)
    muted.blend_type, muted.mute = "COMBINE", True
    action_adapter.assign(rig, layer)
    data.action_blend_type, data.action_influence = "COMBINE", 0.4
    _assert_as_blender(rig, list(dict.fromkeys(names)), np.arange(-5, 260))


def _layer_action(rig):
    """An action keying Spine1's Euler X and Z, the hips' location Z and scale Y, RightArm's quaternion, and
    RightHand's quaternion on muted curves."""
    action = action_adapter.new_action("Layer", rig)
    keys = [("Spine1", "rotation_euler", 0, 0.1, -0.3), ("Spine1", "rotation_euler", 2, 0.2, 0.1),
            ("Hips", "location", 2, 0.02, -0.05), ("Hips", "scale", 1, 1.1, 0.9)]
    keys += [("RightArm", "rotation_quaternion", i, v, v * (1 - 0.1 * i)) for i, v in enumerate((0.95, 0.1, 0.2, 0.05))]
    keys += [("RightHand", "rotation_quaternion", i, 0.5, 0.5) for i in range(4)]
    for role, path, index, first, last in keys:
        bone = helpers.rig_bone(rig, role)
        fcurve = action.new_fcurve(f'pose.bones["{bone}"].{path}', index, bone)
        action_adapter.write_keys(fcurve, np.array([1.0, 40.0]), np.array([first, last]))
        fcurve.mute = role == "RightHand"
    return action


def _strip(track, start, target):
    strip = track.strips.new(target.action.name, start, target.action)
    if action_adapter.LAYERED:
        strip.action_slot = target.slot
    return strip


def test_copies_of_keyed_bones_evaluate_as_blender_plays_them(settings):
    """Copy Rotation (pose space, half influence), Copy Transforms (world space, full and 0.3) and Copy Location
    (world space, 0.7, on a connected bone, which keeps its head) from keyed control bones, on an armature turned,
    moved and scaled in the scene."""
    rig = helpers.load_sample_rig()
    rig.rotation_euler, rig.scale, rig.location = (0.1, 0.2, 0.3), (1.3, 1.3, 1.3), (1.0, 2.0, 0.0)
    _add_controls(rig)
    names = _key_everything(rig)
    for control in ("CTRL_A", "CTRL_B"):
        bone = rig.pose.bones[control]
        for frame in range(1, 131, 17):
            angle = 0.4 * math.sin(0.05 * frame + len(control))
            bone.rotation_quaternion = (math.cos(angle), 0.3 * math.sin(angle), math.sin(angle), 0.1)
            bone.location = (0.1 * angle, 0.0, -0.05 * angle)
            bone.keyframe_insert("rotation_quaternion", frame=frame)
            bone.keyframe_insert("location", frame=frame)
    for role, kind, control, space, influence in (("Spine1", "COPY_ROTATION", "CTRL_A", "POSE", 0.5),
                                                  ("RightArm", "COPY_TRANSFORMS", "CTRL_B", "WORLD", 1.0),
                                                  ("Neck", "COPY_LOCATION", "CTRL_A", "WORLD", 0.7),
                                                  ("LeftArm", "COPY_TRANSFORMS", "CTRL_B", "WORLD", 0.3)):
        constraint = rig.pose.bones[helpers.rig_bone(rig, role)].constraints.new(kind)
        constraint.target, constraint.subtarget, constraint.influence = rig, control, influence
        constraint.owner_space = constraint.target_space = space
    assert rig.data.bones[helpers.rig_bone(rig, "Neck")].use_connect
    names += [helpers.rig_bone(rig, "Head"), helpers.rig_bone(rig, "RightHand")]
    _assert_as_blender(rig, list(dict.fromkeys(names)), np.arange(-5, 140))


def _add_controls(rig):
    """Two control bones, CTRL_A at the root and CTRL_B under the hips, off any bone's rest and rolled; the neck
    connected to its parent (Blender 5.0's FBX importer connects it, 4.2's and 4.5's do not)."""
    helpers.activate(rig)
    bpy.ops.object.mode_set(mode="EDIT")
    edit_bones = rig.data.edit_bones
    for name, parent in (("CTRL_A", None), ("CTRL_B", helpers.rig_bone(rig, "Hips"))):
        bone = edit_bones.new(name)
        bone.head, bone.tail, bone.roll = (0.3, 0.1, 1.0), (0.3, 0.4, 1.1), 0.4
        bone.parent = edit_bones[parent] if parent else None
    edit_bones[helpers.rig_bone(rig, "Neck")].use_connect = True
    bpy.ops.object.mode_set(mode="OBJECT")
