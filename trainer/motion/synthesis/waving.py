"""Waving."""

import numpy as np

from .arms import OPEN_HAND, arm_prefix, neutral_body, place_arm, pose_neutral_arm, shape_hand
from .pointing import aim_head, turn_torso
from .pose import FORWARD, OTHER_ARM, SIDE_SIGN, UP, Pose, bone_length, frame_from, unit

_ADDRESSEE = np.array([0.0, -2.5, 1.62])  # whom the character waves at: ahead, at eye height


def wave_pose(arm, exaggeration, style, phase, envelope):
    """Raised-arm wave poses (T,) at oscillation `phase` (T,) rad, scaled by `envelope` (T,) in [0, 1].

    Both arm segments move in one plane that faces forward and out, so the elbow works as a hinge:
    the forearm sways about the elbow; the upper arm joins in (leading a little) as exaggeration
    grows; the wrist lags behind the forearm (overlapping action)."""
    e = float(exaggeration)
    side, sign = arm_prefix(arm), SIDE_SIGN[arm]
    pose = Pose({name: np.broadcast_to(m, phase.shape + (3, 3)) for name, m in neutral_body().local.items()})

    lean = -sign * (0.02 + 0.05 * e + 0.015 * e * envelope * np.sin(phase - 0.6))
    turn_torso(pose, lean[:, None] * np.array([0.0, 1.0, 0.0]))
    aim_head(pose, _ADDRESSEE + np.array([0.0, 0.0, 0.25 * e]),
              tilt=np.full(phase.shape, -sign * style.head_tilt * (0.7 + 0.6 * e)))
    pose_neutral_arm(pose, OTHER_ARM[arm], elbow_bend=0.32)

    amplitude = (0.22 + 0.38 * e) * envelope                       # forearm sway, rad
    upper_amplitude = (0.08 + 0.42 * e) * amplitude                # whole-arm involvement
    flap = (0.22 - 0.1 * e) * envelope * np.sin(phase - 0.8)       # wrist, lagging
    upper_angle = 0.75 + 1.45 * e + upper_amplitude * np.sin(phase + 0.5)
    fore_angle = 2.85 + 0.2 * e + amplitude * np.sin(phase)

    rise = 0.05 + 0.3 * e + 0.25 * upper_amplitude * np.sin(phase + 0.5)
    pose.turn(side + "Shoulder", rise[:, None] * (-sign * np.array([0.0, 1.0, 0.0])))

    tilt = 0.45 - 0.15 * e  # plane turned forward from the frontal plane
    lateral = np.array([sign * np.cos(tilt), -np.sin(tilt), 0.0])

    def in_plane(angle):
        return np.cos(angle)[:, None] * -UP + np.sin(angle)[:, None] * lateral

    shoulder = pose.head(side + "Arm")
    upper, lower = bone_length(side + "ForeArm", side + "Arm"), bone_length(side + "Hand", side + "ForeArm")
    elbow = shoulder + upper * in_plane(upper_angle)
    wrist = elbow + lower * in_plane(fore_angle)
    palm_forward = unit(FORWARD + 0.25 * sign * np.array([1.0, 0.0, 0.0]))
    hand_y = in_plane(fore_angle + flap + 0.06)
    hand = frame_from([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], hand_y, np.broadcast_to(-palm_forward, hand_y.shape))
    place_arm(pose, arm, elbow, wrist, hand)
    shape_hand(pose, arm, OPEN_HAND, spread=True)
    return pose
