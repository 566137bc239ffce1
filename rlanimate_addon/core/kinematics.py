"""Forward kinematics of the canonical skeleton in numpy, for planning and checks.

The environment the agent learns in is real Blender (trainer/blender_io/fk_env.py); this mirrors Blender's
pose evaluation (pose = parent_pose @ parent_rest^-1 @ rest @ basis) so that bpy-free code, such as
the clip generator's inverse kinematics, can predict what Blender will show.
"""
from collections.abc import Collection, Mapping

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import skeleton, spaces
from .rotations import rotvec_to_matrix

_INDEX = {name: i for i, name in enumerate(skeleton.BONE_NAMES)}
_PARENT = np.array([-1 if b.parent is None else _INDEX[b.parent] for b in skeleton.BONES])
_REST = skeleton.rest_matrices()
# Rest of each bone relative to its parent's rest: parent_rest^-1 @ rest, (B, 4, 4).
_REST_LOCAL = np.array([_REST[i] if p < 0 else np.linalg.inv(_REST[p]) @ _REST[i] for i, p in enumerate(_PARENT)])


def bone_index(name: str) -> int:
    return _INDEX[name]


def pose_matrices(local_rotvecs: Mapping[str, ArrayLike],
                  only: Collection[str] | None = None) -> npt.NDArray[np.float64]:
    """Armature-space pose matrices (..., B, 4, 4) from {bone name: (..., 3) local rotation vector}.

    Bones not named keep their rest rotation. Every value must share one batch shape. only: bone
    names; when given, just they and their ancestors are evaluated (a quicker pass for code that reads
    a few bones) and every other bone's matrix is NaN.
    """
    batch = np.shape(next(iter(local_rotvecs.values())))[:-1] if local_rotvecs else ()
    evaluated = range(len(_PARENT)) if only is None else ancestors(only)
    posed = [name for name in local_rotvecs if _INDEX[name] in evaluated]
    basis = np.broadcast_to(np.eye(4), batch + (len(posed), 4, 4)).copy()  # the posed bones' only
    if posed:  # converted at once: each rotation as it would be alone
        basis[..., :3, :3] = rotvec_to_matrix(np.stack([local_rotvecs[name] for name in posed], axis=-2))
    column = {_INDEX[name]: k for k, name in enumerate(posed)}
    at_rest = np.broadcast_to(np.eye(4), batch + (4, 4))
    pose = np.full(batch + (len(skeleton.BONES), 4, 4), np.nan)
    for i in evaluated:
        local = _REST_LOCAL[i] @ (basis[..., column[i], :, :] if i in column else at_rest)
        parent = _PARENT[i]
        pose[..., i, :, :] = local if parent < 0 else pose[..., parent, :, :] @ local
    return pose


def ancestors(names: Collection[str]) -> list[int]:
    """Sorted indices of the named bones and all their ancestors (parents come before children)."""
    indices: set[int] = set()
    for name in names:
        i = _INDEX[name]
        while i >= 0 and i not in indices:
            indices.add(i)
            i = int(_PARENT[i])
    return sorted(indices)


def head_positions(pose: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """(..., B, 4, 4) pose matrices -> (..., B, 3) bone head positions."""
    return pose[..., :3, 3]


_DESCRIBED = tuple(sorted({b for _, b in skeleton.DESCRIPTION_JOINTS}
                          | {b for _, start, end in skeleton.EFFECTORS for b in (start, end) if b}))


def describe(action_rotvecs: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 42) descriptions (spaces.describe) of the canonical skeleton posed by action-joint
    rotations (..., 15, 3): what the Blender environment reports, without Blender."""
    rotvecs = np.asarray(action_rotvecs, dtype=np.float64)
    pose = pose_matrices({j: rotvecs[..., k, :] for k, j in enumerate(skeleton.ACTION_JOINTS)}, only=_DESCRIBED)
    heads = head_positions(pose)
    positions = {name: heads[..., _INDEX[name], :] for name in _DESCRIBED}
    eyes = {name: pose[..., _INDEX[name], :3, 1] for name in ("LeftEye", "RightEye")}
    return spaces.describe(positions, eyes)
