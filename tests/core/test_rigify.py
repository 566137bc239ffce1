"""A Rigify arm in IK switched to FK for a gesture: the switch's keys and the FK controls snapped onto the
pose the arm plays (core.rigify)."""
import numpy as np

from rlanimate_addon.core import gesture, rigify
from rlanimate_addon.core.rotations import rotvec_to_matrix


def test_the_switch_goes_to_fk_early_in_the_blend_and_comes_back_to_its_own_value():
    count = 150
    values = rigify.switch_values(0.2, count, "REPLACE", 0.0)
    weights = gesture.blend_weights(count)
    assert values[0] == values[-1] == 0.2
    assert np.all(values[weights >= rigify.SWITCH_AT] == 1.0)
    rising = values[: count // 2]
    assert np.all(np.diff(rising) >= 0.0) and np.abs(np.diff(np.diff(rising))).max() < 0.1, "no jump, no kink"
    combined = rigify.switch_values(np.full(count, 0.2), count, "COMBINE", 0.5)
    np.testing.assert_allclose(combined, values - 0.2 + 0.5)


def test_snapped_fk_controls_stand_where_the_arm_plays_and_the_fingers_follow():
    rig = gesture.canonical_rig()
    controls = ("RightArm", "RightForeArm", "RightHand")
    rng = np.random.default_rng(2)
    basis = np.tile(np.eye(4), (4, len(rig.skeleton.names), 1, 1))
    for name in controls:
        basis[:, rig.skeleton.index[name], :3, :3] = rotvec_to_matrix(rng.normal(0.0, 0.6, (4, 3)))
    everything = rig.skeleton.names
    played_pose = rig.skeleton.pose_matrices(basis, only=everything)  # the arm as IK plays it
    under_pose = rig.under_pose_at(4).copy()
    for name in controls:  # the FK controls are at rest, the fingers follow the played (ORG) hand
        under_pose[:, rig.skeleton.index[name]] = rig.skeleton.rest[rig.skeleton.index[name]]
    finger = rig.skeleton.index["RightHandIndex1"]
    under_pose[:, finger] = played_pose[:, finger]
    ik_rig = gesture.RigState("IK", rig.skeleton, rig.roles, "Rigify", rig.under_at(4), False, under_pose=under_pose)
    snapped = rigify.snap_fk(ik_rig, controls, {c: played_pose[:, rig.skeleton.index[c]] for c in controls})
    for name in controls + ("RightHandIndex1",):
        i = rig.skeleton.index[name]
        np.testing.assert_allclose(snapped.under_pose[:, i], played_pose[:, i], atol=1e-9)
    check = rig.skeleton.pose_matrices(snapped.under, only=controls)
    for name in controls:
        np.testing.assert_allclose(
            check[:, rig.skeleton.index[name]], played_pose[:, rig.skeleton.index[name]], atol=1e-9
        )
