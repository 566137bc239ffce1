"""Rest geometry and a small batched pose evaluator (same convention as core.kinematics)."""

import numpy as np

from rlanimate_addon.core import frame_rate, skeleton
from rlanimate_addon.core.rotations import matrix_to_rotvec, rotvec_to_matrix

#: The clips' frame rate, the agent's, in whole frames (Blender's scene rate and the manifest's "fps").
FPS = int(frame_rate.AGENT_FPS)

FINGERS = ("Thumb", "Index", "Middle", "Ring", "Pinky")
#: Finger bones each clip animates besides the action joints (Index2/3 stay at rest: the agent
#: cannot move them, so the clips keep them straight).
FINGER_BONES = tuple(f"{side}Hand{finger}{k}" for side in ("Left", "Right") for finger in FINGERS
                     for k in (1, 2, 3) if not (finger == "Index" and k > 1))
ANIMATED_BONES = tuple(skeleton.ACTION_JOINTS) + tuple(b for b in FINGER_BONES if b not in skeleton.ACTION_JOINTS)

UP = np.array([0.0, 0.0, 1.0])
FORWARD = np.array([0.0, -1.0, 0.0])
SIDE_SIGN = {"LEFT": 1.0, "RIGHT": -1.0}  # +X is the character's left
OTHER_ARM = {"LEFT": "RIGHT", "RIGHT": "LEFT"}


_PARENT = {b.name: b.parent for b in skeleton.BONES}
REST = {b.name: skeleton.rest_frame(b) for b in skeleton.BONES}
HEAD = {b.name: np.asarray(b.head, dtype=np.float64) for b in skeleton.BONES}
REST_LOCAL = {n: REST[n] if p is None else REST[p].T @ REST[n] for n, p in _PARENT.items()}
_OFFSET = {n: None if p is None else REST[p].T @ (HEAD[n] - HEAD[p]) for n, p in _PARENT.items()}


def bone_length(child, parent):
    return float(np.linalg.norm(HEAD[child] - HEAD[parent]))


class Pose:
    """Local rotation matrices (..., 3, 3) of some bones; the rest stay at rest."""

    def __init__(self, local=None):
        self.local = dict(local or {})

    def world(self, name):
        """(..., 3, 3) armature-space rotation of a bone; its columns are the bone's axes."""
        parent = _PARENT[name]
        base = REST_LOCAL[name] if parent is None else self.world(parent) @ REST_LOCAL[name]
        return base @ self.local[name] if name in self.local else base

    def head(self, name):
        """(..., 3) armature-space position of a bone's head."""
        parent = _PARENT[name]
        if parent is None:
            return HEAD[name]
        return self.head(parent) + (self.world(parent) @ _OFFSET[name][:, None])[..., 0]

    def set_world(self, name, rotation):
        """Give a bone the armature-space rotation (..., 3, 3), keeping its parent where it is."""
        parent = _PARENT[name]
        base = REST_LOCAL[name] if parent is None else self.world(parent) @ REST_LOCAL[name]
        self.local[name] = np.swapaxes(base, -1, -2) @ rotation

    def turn(self, name, rotvec):
        """Rotate a bone (and so its children) by an armature-space rotation vector (..., 3)."""
        self.set_world(name, rotvec_to_matrix(rotvec) @ self.world(name))

    def rotvecs(self, names):
        return {n: matrix_to_rotvec(self.local[n]) if n in self.local else np.zeros(3) for n in names}


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def perpendicular(v, axis):
    """Unit component of v (..., 3) perpendicular to the unit axis (..., 3)."""
    return unit(v - np.sum(v * axis, axis=-1, keepdims=True) * axis)


def frame_from(primary_local, secondary_local, primary_world, secondary_world):
    """(..., 3, 3) rotation taking primary_local to primary_world, and secondary_local as close as
    it can to secondary_world."""
    def basis(a, b):
        a = unit(a)
        b = perpendicular(b, a)
        return np.stack([a, b, np.cross(a, b)], axis=-1)

    return basis(primary_world, secondary_world) @ np.swapaxes(basis(primary_local, secondary_local), -1, -2)


def axis_rotation(axis, angle):
    """(..., 3, 3) rotation by angle (...) about a unit axis (..., 3)."""
    return rotvec_to_matrix(np.asarray(axis) * np.asarray(angle)[..., None])


def twist_angle(rotation):
    """Angle (...) of the twist about local Y in the swing-twist split of a local rotation."""
    rv = matrix_to_rotvec(rotation)
    angle = np.linalg.norm(rv, axis=-1)
    half = 0.5 * angle
    sin_ratio = np.where(angle > 1e-9, np.sin(half) / np.maximum(angle, 1e-9), 0.5)
    return 2.0 * np.arctan2(rv[..., 1] * sin_ratio, np.cos(half))
