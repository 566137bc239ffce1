"""Arms: analytic two-bone IK with swivel, forearm twist and hand alignment."""

import numpy as np

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.rotations import matrix_to_rotvec, rotvec_to_matrix

from .pose import (
    ANIMATED_BONES,
    FORWARD,
    SIDE_SIGN,
    Pose,
    axis_rotation,
    bone_length,
    frame_from,
    perpendicular,
    twist_angle,
    unit,
)


def arm_prefix(arm):
    return skeleton.ARM_PREFIX[arm]


def elbow_position(shoulder, wrist, swivel_direction, upper, lower):
    """Elbow (..., 3) of the two-bone chain shoulder -> wrist, bent towards swivel_direction."""
    reach = wrist - shoulder
    distance = np.linalg.norm(reach, axis=-1, keepdims=True)
    axis = reach / distance
    along = (upper**2 - lower**2 + distance**2) / (2.0 * distance)
    radius = np.sqrt(np.maximum(upper**2 - along**2, 0.0))
    return shoulder + along * axis + radius * perpendicular(swivel_direction, axis)


def place_arm(pose, arm, elbow, wrist, hand_rotation):
    """Pose the arm so that its elbow and wrist heads land on `elbow`, `wrist` (..., 3) and the hand
    has the armature-space rotation `hand_rotation`. The elbow is a hinge; the forearm takes the
    twist (pronation) so the wrist only bends."""
    side, sign = arm_prefix(arm), SIDE_SIGN[arm]
    shoulder = pose.head(side + "Arm")
    upper_y = unit(elbow - shoulder)
    fore_y = unit(wrist - elbow)
    upper_x = sign * perpendicular(fore_y, upper_y)  # the forearm folds towards local +X (left)
    upper_z = np.cross(upper_x, upper_y)
    pose.set_world(side + "Arm", np.stack([upper_x, upper_y, upper_z], axis=-1))
    forearm = np.stack([np.cross(fore_y, upper_z), fore_y, upper_z], axis=-1)
    for _ in range(3):  # hand rest is a few degrees off the forearm: converge the twist
        pose.set_world(side + "ForeArm", forearm)
        pose.set_world(side + "Hand", hand_rotation)
        twist = twist_angle(pose.local[side + "Hand"])
        forearm = forearm @ axis_rotation(np.array([0.0, 1.0, 0.0]), twist)
    pose.set_world(side + "ForeArm", forearm)
    pose.set_world(side + "Hand", hand_rotation)


def _curl(pose, side, finger, angles, spread=0.0):
    """Flex a finger's three joints by `angles` (rad, towards the palm) and turn its base by `spread`."""
    for k, angle in enumerate(angles, start=1):
        name = f"{side}Hand{finger}{k}"
        pose.local[name] = rotvec_to_matrix(np.array([-angle, 0.0, spread if k == 1 else 0.0]))


_RELAXED_HAND = {"Thumb": (0.15, 0.15, 0.15), "Index": (0.12,), "Middle": (0.2, 0.25, 0.15),
                 "Ring": (0.25, 0.3, 0.2), "Pinky": (0.3, 0.35, 0.22)}
OPEN_HAND = {"Thumb": (0.05, 0.05, 0.05), "Index": (0.04,), "Middle": (0.08, 0.1, 0.06),
              "Ring": (0.12, 0.12, 0.08), "Pinky": (0.16, 0.15, 0.1)}
POINTING_HAND = {"Thumb": (0.35, 0.55, 0.6), "Index": (0.0,), "Middle": (1.35, 1.55, 0.95),
                  "Ring": (1.45, 1.6, 1.0), "Pinky": (1.5, 1.55, 0.95)}
_SPREAD = {"Thumb": 0.0, "Index": 0.0, "Middle": 0.0, "Ring": -0.04, "Pinky": -0.1}


def shape_hand(pose, arm, shape, spread=False):
    """Give the arm's fingers a hand shape (curl angles per finger), fanned out when `spread`."""
    side, sign = arm_prefix(arm), SIDE_SIGN[arm]
    for finger, angles in shape.items():
        _curl(pose, side, finger, angles, sign * _SPREAD[finger] if spread else 0.0)


def pose_neutral_arm(pose, arm, elbow_bend=0.28):
    """Arm hanging relaxed under gravity from wherever the shoulder is: slightly away from the hip,
    elbow bent `elbow_bend` rad (~16 deg), palm towards the thigh."""
    side, sign = arm_prefix(arm), SIDE_SIGN[arm]
    shoulder = pose.head(side + "Arm")
    upper_dir = unit([sign * 0.16, -0.03, -1.0])
    fore_dir = unit(upper_dir * np.cos(elbow_bend) + perpendicular(FORWARD, upper_dir) * np.sin(elbow_bend))
    elbow = shoulder + bone_length(side + "ForeArm", side + "Arm") * upper_dir
    wrist = elbow + bone_length(side + "Hand", side + "ForeArm") * fore_dir
    hand_y = unit(fore_dir * np.cos(0.12) + perpendicular(FORWARD, fore_dir) * np.sin(0.12))
    # Palm faces the thigh and a little back; the hand's local Z is minus the palm normal.
    hand = frame_from([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], hand_y, [sign * 1.0, -0.25, 0.0])
    place_arm(pose, arm, elbow, wrist, hand)
    shape_hand(pose, arm, _RELAXED_HAND, spread=True)


def neutral_body():
    pose = Pose()
    for arm in skeleton.ARMS:
        pose_neutral_arm(pose, arm)
    return pose


def neutral_pose():
    """{bone: (3,) local rotation vector} of the shared start and end pose, for ANIMATED_BONES."""
    return neutral_body().rotvecs(ANIMATED_BONES)


_CHEST = "Spine2"


def _arc(start, end, progress):
    """Rotations (T, 3, 3) that carry the unit vector `start` along its great circle towards `end`
    ((T,) 3), by the fraction `progress` (T,) of the way."""
    frames = np.shape(progress)
    d0 = np.broadcast_to(start, frames + (3,))
    d1 = np.broadcast_to(end, frames + (3,))
    axis = np.cross(d0, d1)
    sine = np.linalg.norm(axis, axis=-1)
    angle = np.arctan2(sine, np.sum(d0 * d1, axis=-1))
    axis = axis / np.maximum(sine, 1e-12)[..., None]
    return rotvec_to_matrix(axis * (np.asarray(progress) * angle)[..., None])


def _apply(rotation, vector):
    return (rotation @ vector[..., None])[..., 0]


def arm_keys(pose, arm):
    """Where `pose` puts the arm, in the chest's frame: the directions of the wrist and of the elbow
    from the shoulder, the wrist's distance, and the hand's rotation."""
    side = arm_prefix(arm)
    to_chest = np.swapaxes(pose.world(_CHEST), -1, -2)
    shoulder = pose.head(side + "Arm")
    reach = (to_chest @ (pose.head(side + "Hand") - shoulder)[..., None])[..., 0]
    elbow = (to_chest @ (pose.head(side + "ForeArm") - shoulder)[..., None])[..., 0]
    distance = np.linalg.norm(reach, axis=-1)
    return {"wrist": reach / distance[..., None], "distance": distance, "elbow": unit(elbow),
            "hand": to_chest @ pose.world(side + "Hand")}


def move_arm(pose, arm, start, end, progress, hand_progress, fold=0.0):
    """Pose the arm on every frame between two `arm_keys`. The wrist travels on a great-circle arc
    about the shoulder with its distance eased (shortened by `fold` mid-way, so the elbow bends to
    swing the arm and extends again), the elbow's direction swings on its own arc (the swivel), and
    the hand turns by `hand_progress`. Progress (T,) may leave [0, 1] for anticipation and overshoot."""
    side = arm_prefix(arm)
    frames = progress.shape
    upper, lower = bone_length(side + "ForeArm", side + "Arm"), bone_length(side + "Hand", side + "ForeArm")
    distance = start["distance"] + progress * (end["distance"] - start["distance"])
    distance = np.minimum(distance * (1.0 - fold * np.sin(np.pi * np.clip(progress, 0, 1)) ** 2),
                          0.999 * (upper + lower))
    hand_start = np.broadcast_to(start["hand"], frames + (3, 3))
    hand_turn = matrix_to_rotvec(np.swapaxes(hand_start, -1, -2) @ end["hand"])
    hand = hand_start @ rotvec_to_matrix(np.asarray(hand_progress)[..., None] * hand_turn)

    # The elbow's offset from the shoulder-wrist line rides along with the wrist's arc (parallel
    # transport), turning evenly about that line to its end swivel: no fixed reference, no flips.
    carry = _arc(start["wrist"], end["wrist"], progress)
    direction = _apply(carry, np.broadcast_to(start["wrist"], frames + (3,)))
    offset = np.broadcast_to(perpendicular(start["elbow"], start["wrist"]), frames + (3,))
    carried = _apply(_arc(start["wrist"], end["wrist"], np.ones(frames)), offset)
    target = perpendicular(end["elbow"], end["wrist"])
    swivel = np.arctan2(np.sum(np.cross(carried, target) * end["wrist"], axis=-1), np.sum(carried * target, axis=-1))
    hint = _apply(rotvec_to_matrix(direction * (progress * swivel)[..., None]), _apply(carry, offset))

    chest = pose.world(_CHEST)
    shoulder = pose.head(side + "Arm")
    wrist = shoulder + _apply(chest, distance[..., None] * direction)
    elbow = elbow_position(shoulder, wrist, _apply(chest, hint), upper, lower)
    place_arm(pose, arm, elbow, wrist, chest @ hand)
