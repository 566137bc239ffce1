"""RigSkeleton: forward kinematics, and the pose predicted from an evaluated pose when bones change."""
import numpy as np

from rlanimate_addon.core import gesture
from rlanimate_addon.core.rotations import rotvec_to_matrix

RNG = np.random.default_rng(2)


def _random_basis(count, bones, scale):
    basis = np.tile(np.eye(4), (count, bones, 1, 1))
    basis[..., :3, :3] = rotvec_to_matrix(RNG.normal(scale=scale, size=(count, bones, 3)))
    basis[..., :3, 3] = RNG.normal(scale=0.01, size=(count, bones, 3))
    return basis


def test_pose_after_matches_forward_kinematics_of_the_new_basis_on_a_plain_hierarchy():
    skeleton = gesture.canonical_rig().skeleton
    every = list(skeleton.names)
    under = _random_basis(6, len(every), 0.3)
    pose = skeleton.pose_matrices(under, only=every)
    changed = [skeleton.index[n] for n in ("Spine1", "RightArm", "RightHand", "LeftForeArm")]
    new = under.copy()
    new[:, changed] = _random_basis(6, len(changed), 1.0)
    predicted = skeleton.pose_after(pose, under, new, changed, only=every)
    assert np.allclose(predicted, skeleton.pose_matrices(new, only=every), atol=1e-12)
    tip = "RightHandIndex4"
    partial = skeleton.pose_after(pose, under, new, changed, only=(tip,))
    chain = skeleton.ancestors(tip)
    assert np.allclose(partial[:, chain], predicted[:, chain], atol=1e-12)
    left = skeleton.index["LeftHand"]
    assert np.allclose(partial[:, left], pose[:, left]), "bones off the chain keep the pose underneath"


def test_a_bone_that_follows_its_parent_role_through_helpers_moves_rigidly_with_it():
    """A role skeleton whose parent links stand for constraint-driven helper bones: the evaluated pose
    carries the offset the helpers add, and a turned parent carries the child with that offset."""
    skeleton = gesture.canonical_rig().skeleton
    every = list(skeleton.names)
    under = _random_basis(3, len(every), 0.2)
    pose = skeleton.pose_matrices(under, only=every)
    hand = skeleton.index["RightHand"]
    offset = np.eye(4)
    offset[:3, :3] = rotvec_to_matrix(np.array([0.0, 0.4, 0.0]))
    pose_with_helper = pose.copy()
    for i in [hand] + [i for i in range(len(every)) if hand in skeleton.ancestors(every[i])[:-1]]:
        pose_with_helper[:, i] = pose[:, skeleton.index["RightForeArm"]] @ offset @ np.linalg.inv(
            pose[:, skeleton.index["RightForeArm"]]) @ pose[:, i]
    forearm = skeleton.index["RightForeArm"]
    new = under.copy()
    new[:, forearm] = _random_basis(3, 1, 1.0)[:, 0]
    predicted = skeleton.pose_after(pose_with_helper, under, new, [forearm], only=("RightHand",))
    relative_before = np.linalg.inv(pose_with_helper[:, forearm]) @ pose_with_helper[:, hand]
    relative_after = np.linalg.inv(predicted[:, forearm]) @ predicted[:, hand]
    assert np.allclose(relative_after, relative_before, atol=1e-12)


def test_inverse_of_rigid_and_scaled_affine_matrices():
    from rlanimate_addon.core.rig import inverse

    rigid = _random_basis(4, 3, 1.0)
    assert np.allclose(inverse(rigid) @ rigid, np.eye(4), atol=1e-12)
    scaled = rigid.copy()
    scaled[..., :3, :3] *= 0.01
    assert np.allclose(inverse(scaled) @ scaled, np.eye(4), atol=1e-9)



def test_inverses_of_a_still_rig_are_taken_once_with_the_same_bits_as_frame_by_frame():
    """A rig standing still hands pose_after one frame broadcast over the gesture's frames (stride 0): its
    inverses are taken once and repeated, and must be the frame-by-frame ones bit for bit, for rigid bones
    (by transposition) and with a scaled bone (np.linalg.inv)."""
    from rlanimate_addon.core.rig import _frames_inverse, inverse
    for scale in (1.0, 1.2):
        still = _random_basis(1, 12, 0.5)
        still[0, 3, :3, :3] *= scale
        frames = np.broadcast_to(still, (120, 12, 4, 4))
        bones = [0, 3, 5, 11]
        assert frames.strides[0] == 0
        once = _frames_inverse(frames, bones)
        assert once.shape == (120, 4, 4, 4) and once.flags.c_contiguous
        assert np.array_equal(once, inverse(np.array(frames)[:, bones]))
        assert np.allclose(once @ frames[:, bones], np.eye(4), atol=1e-12)


def test_inverse_takes_the_transpose_exactly_where_the_rotation_parts_are_orthonormal_to_1e6():
    """The orthonormality test behind `inverse` decides as np.allclose(R^T R, I, atol=1e-6) does."""
    from rlanimate_addon.core.rig import _orthonormal
    rigid = _random_basis(40, 7, 1.0)[..., :3, :3]
    assert _orthonormal(rigid) and _orthonormal(np.broadcast_to(rigid[:1], rigid.shape))
    for row, column, offset in ((0, 0, 4e-6), (2, 1, 4e-7), (1, 2, 8e-7), (0, 0, np.nan)):
        bent = rigid.copy()
        bent[17, 3, row, column] += offset
        expected = bool(np.allclose(np.swapaxes(bent, -1, -2) @ bent, np.eye(3), atol=1e-6))
        assert _orthonormal(bent) == expected
    assert not _orthonormal(rigid * 1.01)
