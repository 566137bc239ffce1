"""Pointing."""

import numpy as np

from rlanimate_addon.core import skeleton, spaces
from rlanimate_addon.core.rotations import matrix_to_rotvec

from .arms import POINTING_HAND, arm_prefix, elbow_position, neutral_body, place_arm, pose_neutral_arm, shape_hand
from .pose import (
    FORWARD,
    HEAD,
    OTHER_ARM,
    REST,
    SIDE_SIGN,
    UP,
    axis_rotation,
    bone_length,
    frame_from,
    perpendicular,
    unit,
)


def aim_head(pose, look_at, tilt=0.0, neck_share=0.4):
    """Turn neck and head (yaw, then pitch; the eyes ride on the head) so the eyes look at `look_at`."""
    for _ in range(2):  # the eyes sit in front of the neck pivot: one correction removes parallax
        eyes = 0.5 * (pose.head("LeftEye") + pose.head("RightEye"))
        current = unit(pose.world("LeftEye")[..., :, 1])
        wanted = unit(np.asarray(look_at) - eyes)
        yaw = np.arctan2(wanted[..., 0], -wanted[..., 1]) - np.arctan2(current[..., 0], -current[..., 1])
        yaw = (yaw + np.pi) % (2 * np.pi) - np.pi
        turned = (axis_rotation(UP, yaw) @ current[..., None])[..., 0]
        pitch = np.arcsin(np.clip(wanted[..., 2], -1, 1)) - np.arcsin(np.clip(turned[..., 2], -1, 1))
        lateral = perpendicular(np.cross(turned, UP), UP)
        rotation = axis_rotation(lateral, pitch) @ axis_rotation(UP, yaw)
        rotvec = matrix_to_rotvec(rotation)
        pose.turn("Neck", neck_share * rotvec)
        pose.turn("Head", (1.0 - neck_share) * rotvec)
        neck_share = 0.0
    if np.any(tilt):
        pose.turn("Head", np.asarray(tilt)[..., None] * unit(pose.world("LeftEye")[..., :, 1]))


def turn_torso(pose, rotvec, shares=(0.3, 0.35, 0.35)):
    for bone, share in zip(("Spine", "Spine1", "Spine2"), shares, strict=True):
        pose.turn(bone, share * np.asarray(rotvec))


def pointing_geometry(arm, target):
    """Azimuth (0 ahead, + out to the arm's side, - across the body), elevation and distance."""
    sign = SIDE_SIGN[arm]
    direction = spaces.pointing_direction(arm, target)
    azimuth = np.arctan2(sign * direction[0], -direction[1])
    elevation = np.arcsin(np.clip(direction[2], -1.0, 1.0))
    distance = np.linalg.norm(np.asarray(target) - skeleton.shoulder_rest_position(arm))
    return direction, azimuth, elevation, distance


def pointing_hold(arm, target, style):
    """The hold pose of a pointing gesture; the other arm stays neutral."""
    pose = neutral_body()
    side, sign = arm_prefix(arm), SIDE_SIGN[arm]
    direction, azimuth, elevation, distance = pointing_geometry(arm, target)

    # Torso: turn a fraction of the way towards the target (more when it is across the body) and
    # lean a little towards it, more for low and far targets.
    yaw = 0.2 * azimuth + 0.22 * min(azimuth, 0.0)
    horizontal = unit([direction[0], direction[1], 0.0]) if np.hypot(*direction[:2]) > 1e-3 else FORWARD
    lean = 0.03 + 0.025 * (distance - 1.5) + 0.22 * max(-elevation, 0.0) - 0.05 * max(elevation, 0.0)
    lean_axis = np.cross(UP, horizontal)
    turn_torso(pose, sign * yaw * UP)
    turn_torso(pose, lean * lean_axis)

    # Gaze leads to the target; the eyes follow the head.
    aim_head(pose, np.asarray(target, dtype=np.float64), tilt=0.3 * style.head_tilt * -sign)
    # The free arm keeps hanging under gravity however the torso turns and leans, elbow a bit softer.
    pose_neutral_arm(pose, OTHER_ARM[arm], elbow_bend=0.36)

    # Clavicle: rises once the arm is above the shoulder, comes forward for targets ahead/across.
    rise = 0.32 * max(elevation + 0.1, 0.0)
    protraction = 0.1 * np.cos(elevation) * max(np.cos(azimuth), 0.0) + 0.12 * max(-azimuth, 0.0)
    pose.turn(side + "Shoulder", rise * sign * -np.array([0.0, 1.0, 0.0]) + protraction * -sign * UP)

    # Hand: the index finger along the pointing ray, palm down and rolled towards the body.
    hand_rest = REST[side + "Hand"]
    finger_local = hand_rest.T @ unit(HEAD[side + "HandIndex4"] - HEAD[side + "HandIndex1"])
    base_local = hand_rest.T @ (HEAD[side + "HandIndex1"] - HEAD[side + "Hand"])
    down = perpendicular(-UP, direction) if abs(direction[2]) < 0.97 else perpendicular(FORWARD, direction)
    medial = perpendicular(np.cross(direction, down) * -sign, direction)
    roll = style.palm_roll + 0.4 * max(elevation, 0.0)
    palm_normal = np.cos(roll) * down + np.sin(roll) * medial
    hand = frame_from(finger_local, [0.0, 0.0, 1.0], direction, -palm_normal)  # local Z = -palm normal

    # Wrist on the ray: index base = rest shoulder + lambda * direction, at the chosen reach.
    shoulder = pose.head(side + "Arm")
    upper, lower = bone_length(side + "ForeArm", side + "Arm"), bone_length(side + "Hand", side + "ForeArm")
    reach = style.extension * (upper + lower)
    offset = skeleton.shoulder_rest_position(arm) - hand @ base_local - shoulder
    along = offset @ direction
    lam = -along + np.sqrt(along**2 - offset @ offset + reach**2)
    wrist = skeleton.shoulder_rest_position(arm) + lam * direction - hand @ base_local

    # Elbow: hangs down and out, more out for high and across-body targets.
    swivel = 0.45 + 0.35 * max(elevation, 0.0) + 0.3 * max(-azimuth, 0.0) + style.swivel
    axis = unit(wrist - shoulder)
    outward = perpendicular(sign * np.array([1.0, 0.0, 0.0]) + 0.3 * UP, axis)
    hang = perpendicular(-UP + 0.2 * sign * np.array([1.0, 0.0, 0.0]), axis)
    elbow = elbow_position(shoulder, wrist, np.cos(swivel) * hang + np.sin(swivel) * outward, upper, lower)
    place_arm(pose, arm, elbow, wrist, hand)

    shape_hand(pose, arm, POINTING_HAND)
    pose.local[side + "HandIndex1"] = np.eye(3)
    return pose
