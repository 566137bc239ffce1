import numpy as np

from rlanimate_addon.core import kinematics, skeleton


def test_rest_pose_heads_are_the_spec_heads():
    heads = kinematics.head_positions(kinematics.pose_matrices({}))
    np.testing.assert_allclose(heads, [b.head for b in skeleton.BONES], atol=1e-12)


def test_lowering_the_left_arm_swings_the_elbow_down():
    # LeftArm's local X is the character's forward axis (-Y): a negative turn about it lowers the arm.
    pose = kinematics.pose_matrices({"LeftArm": np.array([-1.3, 0.0, 0.0])})
    heads = kinematics.head_positions(pose)
    arm, forearm = kinematics.bone_index("LeftArm"), kinematics.bone_index("LeftForeArm")
    assert np.isclose(np.linalg.norm(heads[forearm] - heads[arm]), 0.28)
    assert np.isclose(heads[forearm][2], heads[arm][2] - 0.28 * np.sin(1.3))
    np.testing.assert_allclose(heads[kinematics.bone_index("RightForeArm")], (-0.45, 0.0, 1.45), atol=1e-12)


def test_batched_poses_match_single_poses():
    rng = np.random.default_rng(3)
    rot = rng.normal(scale=0.4, size=(4, 3))
    batched = kinematics.pose_matrices({"LeftForeArm": rot})
    for i in range(4):
        np.testing.assert_allclose(batched[i], kinematics.pose_matrices({"LeftForeArm": rot[i]}), atol=1e-12)


def test_no_bone_rests_near_gimbal_lock_of_the_euler_keys_an_fbx_file_stores():
    # FBX stores a bone's rotation relative to its parent as XYZ Euler angles (R = Rz Ry Rx); at Y = +-90
    # degrees the decomposition is singular and a frame with a tiny turn reads back millimetres off.
    for bone in skeleton.BONES:
        if bone.parent is None:
            continue
        relative = skeleton.rest_frame(skeleton.BONE_BY_NAME[bone.parent]).T @ skeleton.rest_frame(bone)
        euler_y = np.degrees(np.arcsin(np.clip(-relative[2, 0], -1.0, 1.0)))
        assert abs(euler_y) < 80.0, f"{bone.name} rests {90 - abs(euler_y):.1f} degrees from gimbal lock"


def test_evaluating_only_some_bones_gives_their_full_pose_and_nan_elsewhere():
    rng = np.random.default_rng(5)
    local = {name: rng.normal(scale=0.5, size=(6, 3)) for name in skeleton.ACTION_JOINTS}
    full = kinematics.pose_matrices(local)
    only = ("RightArm", "RightHandIndex4")
    partial = kinematics.pose_matrices(local, only=only)
    chain = {kinematics.bone_index(n) for n in ("Hips", "Spine", "Spine1", "Spine2", "RightShoulder", "RightArm",
                                                 "RightForeArm", "RightHand", "RightHandIndex1", "RightHandIndex2",
                                                 "RightHandIndex3", "RightHandIndex4")}
    for i in range(len(skeleton.BONES)):
        if i in chain:
            np.testing.assert_allclose(partial[:, i], full[:, i], atol=1e-12)
        else:
            assert np.isnan(partial[:, i]).all(), skeleton.BONES[i].name
