"""Raising a hand: to ask a question, volunteer or be seen, higher with more exaggeration.

The forearm stands near vertical, palm forward and fingers together, held still (no wave). With
exaggeration e the upper arm goes from about level with the shoulder (e = 0: a small, polite raise,
elbow bent near 90 degrees, the hand a little above the head's side) to nearly straight overhead
(e = 1: an eager stretch, elbow almost straight, the collar lifted and the torso leaning away).
"""

import numpy as np

from .arms import OPEN_HAND, arm_prefix, neutral_body, place_arm, pose_neutral_arm, shape_hand
from .pointing import aim_head, turn_torso
from .pose import FORWARD, OTHER_ARM, SIDE_SIGN, UP, bone_length, frame_from, unit

_ADDRESSEE = np.array([0.0, -2.5, 1.62])  # whom the character raises the hand to: ahead, at eye height
#: Upper-arm angle from hanging (rad) at e = 0 and its growth to e = 1; the forearm's angle likewise.
UPPER_ANGLE = (1.6, 1.25)
FORE_ANGLE = (3.0, 0.07)


def raised_hand_pose(arm, exaggeration, style):
    """The held pose of a raised hand at `exaggeration` in [0, 1]; the other arm stays neutral."""
    e = float(exaggeration)
    side, sign = arm_prefix(arm), SIDE_SIGN[arm]
    pose = neutral_body()
    turn_torso(pose, -sign * (0.015 + 0.06 * e) * np.array([0.0, 1.0, 0.0]))  # lean away, counterbalancing
    aim_head(pose, _ADDRESSEE + np.array([0.0, 0.0, 0.15 * e]), tilt=-sign * style.head_tilt * 0.5)
    pose_neutral_arm(pose, OTHER_ARM[arm], elbow_bend=0.32)
    pose.turn(side + "Shoulder", (0.08 + 0.3 * e) * -sign * np.array([0.0, 1.0, 0.0]))  # the collar lifts

    # Both arm segments in one plane turned forward from the frontal plane: the elbow is a hinge.
    tilt = 0.6 - 0.25 * e + 0.5 * style.swivel
    lateral = np.array([sign * np.cos(tilt), -np.sin(tilt), 0.0])

    def in_plane(angle):
        return np.cos(angle) * -UP + np.sin(angle) * lateral

    upper_angle = UPPER_ANGLE[0] + UPPER_ANGLE[1] * e
    fore_angle = FORE_ANGLE[0] + FORE_ANGLE[1] * e
    shoulder = pose.head(side + "Arm")
    upper, lower = bone_length(side + "ForeArm", side + "Arm"), bone_length(side + "Hand", side + "ForeArm")
    elbow = shoulder + upper * in_plane(upper_angle)
    wrist = elbow + lower * in_plane(fore_angle)
    palm_forward = unit(FORWARD - 0.15 * sign * np.array([1.0, 0.0, 0.0]))  # forward, a little inward
    hand = frame_from([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], in_plane(fore_angle + 0.1), -palm_forward)
    place_arm(pose, arm, elbow, wrist, hand)
    shape_hand(pose, arm, OPEN_HAND)
    return pose
