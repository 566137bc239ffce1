"""Guiding ("this way"): an open palm presenting towards a target, as a host shows a guest the way.

Looked at, not copied, from the real "guide" takes (../shared/realmocap/guide, CC BY-NC): the wrist
goes out a little below shoulder height with the elbow soft (the arm 0.88-1.0 of its length), the
fingers run towards where the guest should go, and the palm is turned up and in, towards the body
(40-60 degrees from straight up), held about a second.
"""

import numpy as np

from .arms import OPEN_HAND, arm_prefix, elbow_position, neutral_body, place_arm, pose_neutral_arm, shape_hand
from .pointing import aim_head, pointing_geometry, turn_torso
from .pose import FORWARD, HEAD, OTHER_ARM, REST, SIDE_SIGN, UP, bone_length, frame_from, perpendicular, unit

#: The wrist sits this far (rad) below the target's elevation, within GUIDE_PITCH of the horizontal.
WRIST_DROP = 0.2
GUIDE_PITCH = (-0.55, 0.15)
#: The fingers rise this much (rad) above the wrist's direction: the hand is extended at the wrist.
HAND_LIFT = 0.12
#: The palm turns from straight up towards the body by this (rad) plus the style's palm roll.
PALM_TURN = 0.35
#: Shoulder-to-wrist distance at the hold: the style's pointing reach less this (the elbow stays soft).
SOFT_ELBOW = 0.07


def guide_heading(arm, target):
    """(3,) horizontal unit vector from the arm's rest shoulder towards the target, and the target's
    azimuth and elevation (rad) as `pointing_geometry` gives them."""
    _, azimuth, elevation, _ = pointing_geometry(arm, target)
    sign = SIDE_SIGN[arm]
    return np.array([sign * np.sin(azimuth), -np.cos(azimuth), 0.0]), azimuth, elevation


def guide_hold(arm, target, style):
    """The hold pose of a guiding gesture towards `target` (3,); the other arm stays neutral."""
    pose = neutral_body()
    side, sign = arm_prefix(arm), SIDE_SIGN[arm]
    heading, azimuth, elevation = guide_heading(arm, target)

    # Torso: turns a little towards the way and bows slightly, as a host does.
    turn_torso(pose, sign * 0.15 * azimuth * UP)
    turn_torso(pose, (0.04 + 0.2 * style.head_tilt) * np.cross(UP, FORWARD))
    aim_head(pose, np.asarray(target, dtype=np.float64), tilt=0.5 * style.head_tilt * -sign)
    pose_neutral_arm(pose, OTHER_ARM[arm], elbow_bend=0.36)
    pose.turn(side + "Shoulder", 0.08 * -sign * UP)  # the collar comes forward with the arm

    pitch = float(np.clip(elevation - WRIST_DROP, *GUIDE_PITCH))
    wrist_direction = np.cos(pitch) * heading + np.sin(pitch) * UP
    fingers = np.cos(pitch + HAND_LIFT) * heading + np.sin(pitch + HAND_LIFT) * UP
    up = perpendicular(UP, fingers)
    medial = sign * np.cross(fingers, up)
    roll = PALM_TURN + style.palm_roll
    palm_normal = np.cos(roll) * up + np.sin(roll) * medial
    hand_rest = REST[side + "Hand"]
    finger_local = hand_rest.T @ unit(HEAD[side + "HandIndex4"] - HEAD[side + "HandIndex1"])
    hand = frame_from(finger_local, [0.0, 0.0, 1.0], fingers, -palm_normal)  # local Z = -palm normal

    shoulder = pose.head(side + "Arm")
    upper, lower = bone_length(side + "ForeArm", side + "Arm"), bone_length(side + "Hand", side + "ForeArm")
    wrist = shoulder + (style.extension - SOFT_ELBOW) * (upper + lower) * wrist_direction
    swivel = 0.5 + 0.3 * max(-azimuth, 0.0) + style.swivel  # the elbow hangs down and a little out
    axis = unit(wrist - shoulder)
    outward = perpendicular(sign * np.array([1.0, 0.0, 0.0]) + 0.3 * UP, axis)
    hang = perpendicular(-UP + 0.2 * sign * np.array([1.0, 0.0, 0.0]), axis)
    elbow = elbow_position(shoulder, wrist, np.cos(swivel) * hang + np.sin(swivel) * outward, upper, lower)
    place_arm(pose, arm, elbow, wrist, hand)
    shape_hand(pose, arm, OPEN_HAND)  # fingers together: a presenting hand, not a spread one
    return pose

