"""The relaxed hand a capture without fingers gets (trainer/motion/hands.py)."""
import numpy as np

from rlanimate_addon.core import kinematics, skeleton
from trainer.motion import hands
from trainer.motion.clip import MotionClip


def test_relaxed_hand_curls_the_fingers_towards_the_palm():
    relaxed = hands.relaxed_hand(MotionClip("c", "", 30.0, np.zeros((3, len(skeleton.ACTION_JOINTS), 3))))
    for side in ("Left", "Right"):
        index1 = relaxed.rotvecs[:, skeleton.ACTION_JOINTS.index(side + "HandIndex1")]
        fingers = {k: v[0] for k, v in relaxed.fingers.items()}
        pose = kinematics.pose_matrices({side + "HandIndex1": index1[0], **fingers})
        heads = kinematics.head_positions(pose)
        for finger in ("Index", "Pinky"):
            base = heads[kinematics.bone_index(f"{side}Hand{finger}1")]
            tip = heads[kinematics.bone_index(f"{side}Hand{finger}4")]
            assert tip[2] < base[2] - 0.005  # T-pose, palm down: a curl lowers the tip
        assert np.all(np.isfinite(relaxed.rotvecs))


def test_only_a_clip_without_finger_data_gets_the_relaxed_hand():
    bare = MotionClip("bare", "", 30.0, np.zeros((3, len(skeleton.ACTION_JOINTS), 3)))
    fingered = hands.relaxed_hand(bare)
    assert fingered.fingers and hands.with_hand(fingered) is fingered
    given = hands.with_hand(bare)
    np.testing.assert_array_equal(given.rotvecs, fingered.rotvecs)
    assert not np.array_equal(given.rotvecs, bare.rotvecs)
