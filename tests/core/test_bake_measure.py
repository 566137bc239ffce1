"""Where a gesture puts the hand and finger, and how far a played pose is from there (core.bake_measure)."""
import numpy as np

from rlanimate_addon.core import bake_measure, gesture
from rlanimate_addon.core.rotations import matrix_to_quat, rotvec_to_matrix

RNG = np.random.default_rng(3)


def test_planned_points_are_the_forward_kinematics_of_the_keys():
    rig = gesture.canonical_rig()
    bones = ["RightShoulder", "RightArm", "RightForeArm", "RightHand", "RightHandIndex1"]
    rotvecs = RNG.normal(0.0, 0.5, (5, len(bones), 3))
    pose = bake_measure.planned_pose(rig, "RIGHT", bones, matrix_to_quat(rotvec_to_matrix(rotvecs)))
    basis = np.tile(np.eye(4), (5, len(rig.skeleton.names), 1, 1))
    for k, bone in enumerate(bones):
        basis[:, rig.skeleton.index[bone], :3, :3] = rotvec_to_matrix(rotvecs[:, k])
    expected = rig.skeleton.pose_matrices(basis, only=bake_measure.measured_bones(rig.roles, "RIGHT"))
    points = bake_measure.planned_points(rig, "RIGHT", pose)
    hand = rig.skeleton.index["RightHand"]
    np.testing.assert_allclose(points[:, 0], expected[:, hand, :3, 3], atol=1e-9)
    end = rig.skeleton.index["RightHandIndex3"]
    tip = expected[:, end, :3, 3] + rig.skeleton.lengths[end] * expected[:, end, :3, 1]
    np.testing.assert_allclose(points[:, 2], tip, atol=1e-9)
    assert np.linalg.norm(points[:, 0] - points[0, 0], axis=1).max() > 0.05, "the keys move the wrist"


def test_a_played_pose_off_the_plan_is_measured_in_scene_units_and_degrees():
    planned = np.array([[[0.0, 0.0, 1.0], [0.1, 0.0, 1.0], [0.2, 0.0, 1.0]]])
    played = planned.copy()
    played[0, 0] += (0.03, 0.0, 0.0)  # the wrist 3 cm away
    played[0, 2] = (0.1 + 0.1 * np.cos(np.radians(4.0)), 0.1 * np.sin(np.radians(4.0)), 1.0)  # the finger 4 deg
    distance, angle = bake_measure.misses(planned, played, world_scale=0.01)
    assert np.isclose(distance[0], 0.03 * 0.01) and np.isclose(angle[0], 4.0)
    assert bake_measure.misses(planned, planned, 1.0)[1][0] == 0.0


def test_a_point_is_carried_rigidly_by_its_bone():
    rest = np.eye(4)
    rest[:3, 3] = (1.0, 0.0, 0.0)
    posed = np.eye(4)
    posed[:3, :3] = rotvec_to_matrix(np.array([0.0, 0.0, np.pi / 2]))
    posed[:3, 3] = (0.0, 1.0, 0.0)
    out = bake_measure.carried(posed[None, None], rest[None], np.array([[2.0, 0.0, 0.0]]))
    np.testing.assert_allclose(out[0, 0], (0.0, 2.0, 0.0), atol=1e-12)


def test_the_checked_frames_are_the_apex_and_two_at_full_weight():
    count = 100
    path = np.zeros((count, 3))
    path[:, 0] = np.sin(np.linspace(0.0, np.pi, count)) * np.linspace(1.0, 0.5, count)
    frames = bake_measure.check_frames(count, path)
    full = np.flatnonzero(gesture.blend_weights(count) == 1.0)
    assert len(frames) == 3 and all(f in full for f in frames)
    assert int(np.argmax(path[full, 0])) + full[0] in frames
