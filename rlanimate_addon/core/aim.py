"""Aim correction: turn a pointing gesture's arm so the index-finger line passes through the target.

The agent's own aim is a few degrees off on unseen targets (docs/EXTENSION.md, "Aim correction").
On the canonical skeleton, each frame's finger line (index base b, direction f) is turned about the
posed shoulder joint S (the Arm bone's head) by a rotation R that puts T on the line: in closed
form, the shortest rotation taking the point of the line as far from S as T is onto T. R is applied
to the Arm bone's local rotation, B' = B W^-1 R W (W: the Arm bone's armature-space pose rotation),
with its rotation vector scaled by a pointing-phase weight that ramps with minimum jerk from 0 at
the start of the stroke to 1 by its middle, and back to 0 over the return.
"""
import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import kinematics, skeleton
from .easing import minimum_jerk
from .rotations import matrix_to_rotvec, rotvec_to_matrix

#: The correction fades in while the finger base travels between these fractions of its largest
#: excursion from its start position, and out again while it travels back between the same fractions
#: of its largest excursion from its end position ...
PHASE_RAMP = (0.01, 0.5)
#: ... over at least this share of the gesture's frames: a quicker stroke gets a ramp that starts
#: before it, while the hand is still at rest.
MIN_RAMP_SHARE = 0.2


def _finger_line_ends(arm: str) -> tuple[str, str, str]:
    prefix = skeleton.ARM_PREFIX[arm]
    return prefix + "Arm", prefix + "HandIndex1", prefix + "HandIndex4"


def finger_line_joints(arm: str) -> list[int]:
    """Indices of the action joints (skeleton.ACTION_JOINTS) that `finger_lines` reads: the arm's chain."""
    chain = {skeleton.BONE_NAMES[i] for i in kinematics.ancestors(_finger_line_ends(arm))}
    return [k for k, joint in enumerate(skeleton.ACTION_JOINTS) if joint in chain]


def finger_lines(
    rotvecs: npt.NDArray[np.float64], arm: str,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Posed shoulder S, index base b and unit finger direction f, each (N, 3), and the Arm bone's
    armature-space pose rotation W (N, 3, 3), for canonical action-joint rotations (N, 15, 3), of which
    only the `finger_line_joints` are read."""
    prefix = skeleton.ARM_PREFIX[arm]
    pose = kinematics.pose_matrices({j: rotvecs[:, i] for i, j in enumerate(skeleton.ACTION_JOINTS)},
                                    only=_finger_line_ends(arm))
    heads = kinematics.head_positions(pose)  # (N, B, 3), NaN off the arm's chain
    arm_index = kinematics.bone_index(prefix + "Arm")
    base = heads[:, kinematics.bone_index(prefix + "HandIndex1")]
    finger = heads[:, kinematics.bone_index(prefix + "HandIndex4")] - base
    finger /= np.linalg.norm(finger, axis=1, keepdims=True)
    return heads[:, arm_index], base, finger, pose[:, arm_index, :3, :3]


def rotation_between(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(N, 3, 3) shortest rotations taking unit vectors a (N, 3) onto unit vectors b (N, 3)."""
    axis = np.cross(a, b)
    sin = np.linalg.norm(axis, axis=1)
    angle = np.arctan2(sin, np.sum(a * b, axis=1))
    rotvec = axis * (angle / np.where(sin > 1e-12, sin, 1.0))[:, None]
    return rotvec_to_matrix(rotvec)


def shoulder_corrections(shoulder: npt.NDArray[np.float64], base: npt.NDArray[np.float64],
                         finger: npt.NDArray[np.float64], targets: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(N, 3) armature-space rotation vectors about the shoulder that aim each finger line at its target.

    shoulder, base, targets: (N, 3) positions; finger: (N, 3) unit directions. In the arm's own frame
    the target must lie on the finger line, at the point base + lambda * finger that is as far from the
    shoulder as the target is (the root of |a + lambda f|^2 = |T - S|^2, a = b - S); the correction is
    the shortest rotation taking that point's direction from the shoulder onto the target's. A target
    nearer the shoulder than the finger line passes gets the line's nearest point.
    """
    arm_offset = base - shoulder  # (N, 3)
    to_target = targets - shoulder
    along = np.sum(arm_offset * finger, axis=1)
    reach = np.sum(to_target * to_target, axis=1) - np.sum(arm_offset * arm_offset, axis=1)
    distance = -along + np.sqrt(np.maximum(along ** 2 + reach, 0.0))  # lambda, (N,)
    on_line = arm_offset + distance[:, None] * finger
    return matrix_to_rotvec(rotation_between(_unit(on_line), _unit(to_target)))


def _unit(vectors: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    unit: npt.NDArray[np.float64] = vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
    return unit


def pointing_phase(base: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(N,) weight in [0, 1] for finger-base positions (N, 3): 0 at the first and last frames, 1 from
    the middle of the stroke to the middle of the return.

    The weight is a minimum-jerk ramp in time, from the frame the finger base first leaves
    PHASE_RAMP[0] of its largest distance from its start to the frame it first reaches PHASE_RAMP[1]
    of it, and back down over the mirrored frames of its distance from its end position. A ramp
    shorter than MIN_RAMP_SHARE of the frames starts earlier. Ramping in time spreads the correction
    over the stroke and beyond, even in short gestures whose stroke takes a few frames, and full
    weight from mid-stroke on puts the target on the finger line wherever the apex falls. A finger
    base that does not move gets no correction."""
    count = len(base)
    frames = np.arange(count)
    shortest = int(round(MIN_RAMP_SHARE * count))
    weight = np.ones(count)
    for sign, positions in ((1, base), (-1, base[::-1])):
        travel = np.linalg.norm(positions - positions[0], axis=1)
        if travel.max() < 1e-9:
            return np.zeros(count)
        relative = travel / travel.max()
        start, full = (int(np.argmax(relative >= fraction)) for fraction in PHASE_RAMP)
        start = max(0, min(start, full - shortest))
        ramp = minimum_jerk((frames - start) / max(full - start, 1))
        weight = np.minimum(weight, ramp[::sign])
    return weight


def aim_at(rotvecs: ArrayLike, arm: str, targets: ArrayLike,
           weights: ArrayLike | None = None) -> npt.NDArray[np.float64]:
    """Canonical action-joint rotations (N, 15, 3) with the pointing Arm bone turned towards targets.

    targets: (N, 3) or (3,) positions on the canonical skeleton. weights: (N,) in [0, 1], the share of
    the correction applied per frame; the pointing phase (`pointing_phase`) when None.
    """
    rotvecs = np.asarray(rotvecs, dtype=np.float64)
    shoulder, base, finger, arm_pose = finger_lines(rotvecs, arm)
    targets = np.broadcast_to(np.asarray(targets, dtype=np.float64), base.shape)
    correction = shoulder_corrections(shoulder, base, finger, targets)  # (N, 3)
    if weights is None:
        weights = pointing_phase(base)
    weighted = rotvec_to_matrix(correction * np.asarray(weights, dtype=np.float64)[:, None])  # (N, 3, 3)
    column = skeleton.ACTION_JOINTS.index(skeleton.ARM_PREFIX[arm] + "Arm")
    local = rotvec_to_matrix(rotvecs[:, column])
    pose_t = np.swapaxes(arm_pose, -1, -2)
    aimed = rotvecs.copy()
    aimed[:, column] = matrix_to_rotvec(local @ pose_t @ weighted @ arm_pose)
    return aimed
