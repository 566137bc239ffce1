"""Does a baked gesture play? Where the gesture puts the hand and the finger, and how far the bones the
mesh deforms with are from there, in plain numpy.

The gesture plans each keyed bone's rotation (gesture.gesture_rotations); forward kinematics of the
rig's role bones (RigSkeleton.pose_after, over the pose underneath) gives where the hand and the index
finger will be. After the bake, Blender evaluates the rig as it plays it, constraints, drivers and
helper bones included, and the bones the mesh deforms with carry the same points. A point of a role
bone is carried by a deformed bone rigidly from its rest: p' = pose_D @ rest_D^-1 @ p_rest, so it
needs no assumption about which deformed bone sits where, only that it moves with the role bone.
"""
from collections.abc import Mapping, Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import skeleton
from .gesture import RigState, blend_weights, finger_line_bones
from .rig import each_frame, inverse
from .rotations import quat_to_matrix

#: The deformed hand may sit this far (metres of the scene) from where the gesture put it ...
HAND_TOLERANCE = 0.02
#: ... and the deformed finger line turn this many degrees from the planned one.
FINGER_TOLERANCE_DEG = 3.0


def measured_bones(roles: Mapping[str, str], arm: str) -> tuple[str, str, str]:
    """The role bones carrying the wrist (the hand), the finger base and the finger tip: the finger line
    Exact Aim solves on (gesture.finger_line_bones: from one joint's head through another's, or a hand
    without an index finger along itself)."""
    line = finger_line_bones(roles, arm)
    return roles[skeleton.ARM_PREFIX[arm] + "Hand"], line.start, line.end


def rest_points(rig: RigState, arm: str) -> npt.NDArray[np.float64]:
    """(3, 3) armature-space rest points measured, by `measured_bones`: the wrist (the hand's head), the
    finger line's base and tip (gesture.FingerLine.points: joint positions, or the hand's tail for a hand
    without an index finger)."""
    hand = rig.skeleton.rest_head(rig.roles[skeleton.ARM_PREFIX[arm] + "Hand"])
    return np.stack([hand, *finger_line_bones(rig.roles, arm).points(rig.skeleton, rig.skeleton.rest)])


def planned_pose(rig: RigState, arm: str, bones: Sequence[str],
                 keyed: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(N, B, 4, 4) armature-space pose of the rig's role bones as the gesture plans it: the keyed
    rotations (N, D, 4) on `bones` over the pose underneath; the measured bones (`measured_bones`)
    and their ancestors are updated, the others keep the pose underneath."""
    count = len(keyed)
    measured = measured_bones(rig.roles, arm)
    chain = {i for bone in measured for i in rig.skeleton.ancestors(bone)}
    picked = [k for k, bone in enumerate(bones) if rig.skeleton.index[bone] in chain]  # others move nothing measured
    columns = [rig.skeleton.index[bones[k]] for k in picked]
    under = rig.under_at(count)
    basis = under.copy()
    scale = each_frame(lambda frames: np.linalg.norm(frames[:, columns, :3, :3], axis=-2, keepdims=True),
                       under)  # (N, D, 1, 3)
    basis[:, columns, :3, :3] = quat_to_matrix(np.asarray(keyed, dtype=np.float64)[:, picked]) * scale
    under_pose = rig.under_pose_at(count)
    pose: npt.NDArray[np.float64] = rig.skeleton.pose_after(under_pose, under, basis, columns, only=measured)
    return pose


def planned_points(rig: RigState, arm: str, pose: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(N, 3, 3) wrist, finger base and tip (armature space) carried by the role bones' pose (N, B, 4, 4)."""
    rows = [rig.skeleton.index[b] for b in measured_bones(rig.roles, arm)]
    return carried(pose[:, rows], rig.skeleton.rest[rows], rest_points(rig, arm))


def carried(poses: ArrayLike, rests: ArrayLike, points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(K, P, 3) points (P, 3) at rest, each carried rigidly by its bone: poses (K, P, 4, 4) posed and
    rests (P, 4, 4) rest matrices of the bone carrying each point."""
    homogeneous = np.append(points, np.ones((len(points), 1)), axis=1)  # (P, 4)
    local = np.einsum("pij,pj->pi", inverse(np.asarray(rests, dtype=np.float64)), homogeneous)
    points_posed: npt.NDArray[np.float64] = np.einsum("kpij,pj->kpi", np.asarray(poses, dtype=np.float64), local)
    return points_posed[..., :3]


def turned(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Degrees between the rotations of pose matrices a and b (..., 4, 4)."""
    ra, rb = (m[..., :3, :3] / np.linalg.norm(m[..., :3, :3], axis=-2, keepdims=True) for m in (a, b))
    trace = np.trace(np.swapaxes(ra, -1, -2) @ rb, axis1=-2, axis2=-1)
    degrees: npt.NDArray[np.float64] = np.degrees(np.arccos(np.clip((trace - 1.0) / 2.0, -1.0, 1.0)))
    return degrees


def check_frames(count: int, hand_path: npt.NDArray[np.float64], shown: int | None = None) -> list[int]:
    """Indices of three frames of a gesture of `count` frames to check: its apex (where the planned hand
    (N, 3) is farthest from where it starts), and the frames a third and two thirds of the way through
    the frames the gesture plays at full weight (no blend with the pose underneath, so constraints the
    bake mutes are fully off), of its first `shown` frames (all when None; fewer where a later gesture
    takes over from it)."""
    shown = count if shown is None else min(count, int(shown))
    full = np.flatnonzero(blend_weights(count)[:shown] == 1.0)
    if not len(full):
        full = np.arange(shown)
    apex = full[int(np.argmax(np.linalg.norm(hand_path[full] - hand_path[0], axis=1)))]
    return sorted({int(apex), int(full[len(full) // 3]), int(full[(2 * len(full)) // 3])})


def misses(planned: npt.NDArray[np.float64], played: npt.NDArray[np.float64],
           world_scale: float) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """(hand distances (K,), finger angles in degrees (K,)) between planned and played points (K, 3, 3)
    (wrist, finger base, finger tip in armature space); world_scale: the armature's world scale, so
    distances are the scene's."""
    distance = np.linalg.norm(played[:, 0] - planned[:, 0], axis=1) * world_scale
    a, b = planned[:, 2] - planned[:, 1], played[:, 2] - played[:, 1]
    cos = np.sum(a * b, axis=1) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    return distance, np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
