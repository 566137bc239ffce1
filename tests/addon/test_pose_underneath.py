"""The pose underneath evaluated in numpy from keys (blender/pose_underneath.py) is Blender's own."""
import math

import bpy
import numpy as np

import addon_helpers as helpers
from rlanimate_addon.blender import pose_underneath

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
    from rlanimate_addon.blender import action_adapter
    for fcurve in action_adapter.all_fcurves(action):
        kind = fcurve.data_path.rsplit(".", 1)[1]
        for k, point in enumerate(fcurve.keyframe_points):
            point.interpolation = {"rotation_euler": "LINEAR", "rotation_axis_angle": "CONSTANT"}.get(kind, "BEZIER")
            if kind == "rotation_quaternion" and k % 3 == 1:  # a free handle reaching past the next key
                point.handle_right_type = "FREE"
                point.handle_right = (point.co[0] + 20.0, point.co[1] + 0.4)
        fcurve.update()
    return [b.name for b in bones.values()] + [helpers.rig_bone(rig, "RightHand")]


def _blender(rig, names):
    basis, pose, values = [], [], {n: [] for n in names}
    for frame in FRAMES:
        bpy.context.scene.frame_set(int(frame))
        basis.append([np.array(rig.pose.bones[n].matrix_basis) for n in names])
        pose.append([np.array(rig.pose.bones[n].matrix) for n in names])
        for n in names:
            pb = rig.pose.bones[n]
            path = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}.get(pb.rotation_mode,
                                                                                                 "rotation_euler")
            values[n].append(tuple(getattr(pb, path)))
    return np.array(basis), np.array(pose), {n: np.array(v) for n, v in values.items()}


def _assert_as_blender(rig, names):
    numpy_basis, numpy_pose, numpy_values = pose_underneath.sample(rig, names, FRAMES)
    basis, pose, values = _blender(rig, names)
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
    constraint = arm.constraints.new("COPY_ROTATION")
    assert pose_underneath.sample(rig, names, FRAMES) is None
    arm.constraints.remove(constraint)
    assert pose_underneath.sample(rig, names, FRAMES) is not None
    rig.pose.bones[helpers.rig_bone(rig, "Head")].driver_add("location", 0)
    assert pose_underneath.sample(rig, names, FRAMES) is None
