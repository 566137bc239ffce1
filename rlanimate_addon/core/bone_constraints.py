"""The bone constraints the pose underneath evaluates in numpy (blender/pose_underneath.py), as Blender solves them
(constraint.cc): Copy Transforms, Copy Rotation and Copy Location from another bone of the armature, with every
axis, no offset and no inversion, owner and target in the same space (World or Pose), at any influence.

Each works on 4 x 4 matrices in its space, frames first ((N, 4, 4)). Blender blends a constraint's result with
the matrix before it by the constraint's influence in world space (`interpolate`: the location mixed, the
rotation part of each 3 x 3 (polar decomposition) slerped, its stretch mixed).
"""
import numpy as np
import numpy.typing as npt

from .rotations import matrix_to_quat, quat_to_matrix, rotation_part

Array = npt.NDArray[np.float64]

#: Constraint types evaluated here.
COPYING = ("COPY_TRANSFORMS", "COPY_ROTATION", "COPY_LOCATION")
#: Below this |cos| two quaternions are slerped, above it mixed linearly (Blender's interp_dot_slerp).
_SLERP_LIMIT = 1.0 - 1e-4
#: Above this departure from orthogonal a matrix shears. A rig's rest matrices are single precision, and down a
#: chain of bones their rounding reaches about 1e-6 (Blender 4.2's FBX import of the sample character: 1.1e-6).
_SHEAR = 1e-5


def copy(kind: str, owner: Array, target: Array) -> Array:
    """(N, 4, 4) the owner's matrix after a Copy Transforms, Copy Rotation or Copy Location (REPLACE, every
    axis) of the target's, both in the constraint's space."""
    if kind == "COPY_TRANSFORMS":
        return np.array(target, dtype=np.float64)
    result = np.array(owner, dtype=np.float64)
    if kind == "COPY_LOCATION":
        result[:, :3, 3] = target[:, :3, 3]
        return result
    # Copy Rotation: the target's rotation, normalized, at the owner's scale and location.
    rotation = rotation_part(target)
    result[:, :3, :3] = rotation * np.linalg.norm(owner[:, :3, :3], axis=1, keepdims=True)
    return result


def unsupported(matrices: Array) -> bool:
    """Whether any (N, 4, 4) matrix mirrors (a determinant <= 0) or shears, which these constraints leave to
    Blender (its Copy Rotation reads a sheared target through Euler angles; interpolation flips a mirror)."""
    rotation = rotation_part(matrices)
    gram = np.swapaxes(rotation, -1, -2) @ rotation
    return bool((np.linalg.det(rotation) <= 0.0).any() or np.abs(gram - np.eye(3)).max() > _SHEAR)


def interpolate(before: Array, after: Array, weight: float) -> Array:
    """(N, 4, 4) Blender's interp_m4_m4m4 of two (N, 4, 4) matrices by `weight` (0: before, 1: after)."""
    out = np.array(after, dtype=np.float64)
    out[:, :3, 3] = before[:, :3, 3] * (1.0 - weight) + after[:, :3, 3] * weight
    turn_a, stretch_a = _polar(before[:, :3, :3])
    turn_b, stretch_b = _polar(after[:, :3, :3])
    turn = quat_to_matrix(_slerp(matrix_to_quat(turn_a), matrix_to_quat(turn_b), weight))
    out[:, :3, :3] = turn @ (stretch_a * (1.0 - weight) + stretch_b * weight)
    return out


def _polar(matrices: Array) -> tuple[Array, Array]:
    """((N, 3, 3) rotation, (N, 3, 3) symmetric stretch) with M = rotation @ stretch (by SVD)."""
    left, singular, right = np.linalg.svd(matrices)
    rotation = left @ right
    stretch = np.swapaxes(right, -1, -2) @ (singular[..., :, None] * right)
    return rotation, stretch


def _slerp(a: Array, b: Array, weight: float) -> Array:
    """(N, 4) Blender's interp_qt_qtqt: the shortest arc from a to b, by `weight`."""
    cosine = np.sum(a * b, axis=-1)
    a = np.where((cosine < 0.0)[:, None], -a, a)
    cosine = np.abs(cosine)
    omega = np.arccos(np.clip(cosine, -1.0, 1.0))
    sine = np.sin(omega)
    arc = cosine < _SLERP_LIMIT
    safe = np.where(arc, sine, 1.0)
    first = np.where(arc, np.sin((1.0 - weight) * omega) / safe, 1.0 - weight)
    second = np.where(arc, np.sin(weight * omega) / safe, weight)
    result: Array = first[:, None] * a + second[:, None] * b
    return result
