"""Aim correction: turn a pointing gesture's arm so the index-finger line passes through the target.

The agent's own aim is a few degrees off on unseen targets (docs/EXTENSION.md, "Aim correction").
On the canonical skeleton, each frame's finger line (index base b, direction f) is turned about the
posed shoulder joint S (the Arm bone's head) by the rotation R that lays f onto the target T as
seen from b. Rotating about S moves b too, so R is refined (about ten passes); this converges
because |T - S| (1.5-4 m) is well above |b - S| (an arm's length). R is applied to the Arm bone's
local rotation, B' = B W^-1 R W (W: the Arm bone's armature-space pose rotation), with its rotation
vector scaled by a pointing-phase weight that ramps with minimum jerk from 0 at the start of the
stroke to 1 by its middle, and back to 0 over the return.
"""
import numpy as np

from . import kinematics, skeleton
from .easing import minimum_jerk
from .rotations import matrix_to_rotvec, rotvec_to_matrix

#: Refinements of the shoulder rotation: each one shrinks the residual by about |b - S| / |T - S|
#: (0.2-0.4 for targets 1.5-4 m away); they stop once every frame is within TOLERANCE radians.
MAX_ITERATIONS = 30
TOLERANCE = 1e-5
#: The correction fades in while the finger base travels between these fractions of its largest
#: excursion from its start position, and out again while it travels back between the same fractions
#: of its largest excursion from its end position ...
PHASE_RAMP = (0.01, 0.5)
#: ... over at least this share of the gesture's frames: a quicker stroke gets a ramp that starts
#: before it, while the hand is still at rest.
MIN_RAMP_SHARE = 0.2


def finger_lines(rotvecs, arm):
    """Posed shoulder S, index base b and unit finger direction f, each (N, 3), and the Arm bone's
    armature-space pose rotation W (N, 3, 3), for canonical action-joint rotations (N, 15, 3)."""
    prefix = skeleton.ARM_PREFIX[arm]
    pose = kinematics.pose_matrices({j: rotvecs[:, i] for i, j in enumerate(skeleton.ACTION_JOINTS)},
                                    only=(prefix + "Arm", prefix + "HandIndex1", prefix + "HandIndex4"))
    heads = kinematics.head_positions(pose)  # (N, B, 3), NaN off the arm's chain
    arm_index = kinematics.bone_index(prefix + "Arm")
    base = heads[:, kinematics.bone_index(prefix + "HandIndex1")]
    finger = heads[:, kinematics.bone_index(prefix + "HandIndex4")] - base
    finger /= np.linalg.norm(finger, axis=1, keepdims=True)
    return heads[:, arm_index], base, finger, pose[:, arm_index, :3, :3]


def rotation_between(a, b):
    """(N, 3, 3) shortest rotations taking unit vectors a (N, 3) onto unit vectors b (N, 3)."""
    axis = np.cross(a, b)
    sin = np.linalg.norm(axis, axis=1)
    angle = np.arctan2(sin, np.sum(a * b, axis=1))
    rotvec = axis * (angle / np.where(sin > 1e-12, sin, 1.0))[:, None]
    return rotvec_to_matrix(rotvec)


def shoulder_corrections(shoulder, base, finger, targets):
    """(N, 3) armature-space rotation vectors about the shoulder that aim each finger line at its target.

    shoulder, base, targets: (N, 3) positions; finger: (N, 3) unit directions. The finger line moves
    rigidly with the arm, so each refinement only re-rotates b and f, with no new forward kinematics.
    """
    total = np.broadcast_to(np.eye(3), (len(base), 3, 3))
    arm_offset = base - shoulder  # (N, 3)
    for _ in range(MAX_ITERATIONS):
        moved_base = shoulder + np.einsum("nij,nj->ni", total, arm_offset)
        moved_finger = np.einsum("nij,nj->ni", total, finger)
        wanted = targets - moved_base
        wanted /= np.linalg.norm(wanted, axis=1, keepdims=True)
        step = rotation_between(moved_finger, wanted)
        total = step @ total
        if np.max(np.arccos(np.clip(np.trace(step, axis1=1, axis2=2) * 0.5 - 0.5, -1.0, 1.0))) < TOLERANCE:
            break
    return matrix_to_rotvec(total)


def pointing_phase(base):
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


def aim_at(rotvecs, arm, targets, weights=None):
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
