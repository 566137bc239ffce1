"""The pointing term: how far the agent's own finger line misses the objective's ray, in torch.

The pointing contract (docs/CLIPS.md): at the hold, the index base lies on the ray from the
pointing arm's rest shoulder along the objective's unit vector u, and the finger runs along it, so
the finger's line passes through the target at any distance. Forward kinematics of the canonical
skeleton (core/kinematics.py, here differentiable) turns the animation model's mean pose into the
finger base b and unit direction f; the term per frame is

    |f - u|^2 + |(b - S) - ((b - S) . u) u|^2 / REFERENCE_DISTANCE^2

(the squared angle between finger and ray, plus the base's squared offset from the ray seen from a
target REFERENCE_DISTANCE away), averaged over the frames the reference clip holds its point.
"""
import numpy as np
import torch

from rlanimate_addon.core import kinematics, skeleton, spaces

#: Metres: the nearest target distance the agent is asked to hit (targets are 1.5-4 m away).
REFERENCE_DISTANCE = 1.5
#: A reference frame holds its point when its finger is this close to the ray (radians, metres).
HOLD_ANGLE, HOLD_OFFSET = np.radians(1.0), 0.01

_REST = skeleton.rest_matrices()


def _chain(arm):
    """Bone indices from the root to the arm's index fingertip (HandIndex4), parents first."""
    index = kinematics.bone_index(skeleton.ARM_PREFIX[arm] + "HandIndex4")
    chain = []
    while index >= 0:
        chain.append(index)
        parent = skeleton.BONES[index].parent
        index = -1 if parent is None else kinematics.bone_index(parent)
    return chain[::-1]


class FingerKinematics:
    """Differentiable finger base and direction of each arm from action rotation vectors."""

    def __init__(self):
        self._chains = {}
        for arm in skeleton.ARMS:
            chain = _chain(arm)
            local = [_REST[i] if k == 0 else np.linalg.inv(_REST[chain[k - 1]]) @ _REST[i]
                     for k, i in enumerate(chain)]
            columns = [skeleton.ACTION_JOINTS.index(skeleton.BONES[i].name)
                       if skeleton.BONES[i].name in skeleton.ACTION_JOINTS else None for i in chain]
            self._chains[arm] = (torch.as_tensor(np.array(local)), columns)  # float64; cast to the input's dtype

    def finger(self, rotvecs, arm):
        """rotvecs (..., 15, 3) -> index base (..., 3) and unit finger direction (..., 3)."""
        heads = self.heads(rotvecs, arm)  # (..., K, 3)
        base, tip = heads[..., -4, :], heads[..., -1, :]  # HandIndex1 and HandIndex4 heads
        direction = tip - base
        return base, direction / direction.norm(dim=-1, keepdim=True)

    def wrist(self, rotvecs, arm):
        """rotvecs (..., 15, 3) -> the arm's wrist (its Hand bone's head) (..., 3)."""
        return self.heads(rotvecs, arm)[..., -5, :]

    def heads(self, rotvecs, arm):
        """rotvecs (..., 15, 3) -> the heads (..., K, 3) of the K bones from the root to the index tip."""
        local, columns = self._chains[arm]
        local = local.to(rotvecs.dtype)
        batch = rotvecs.shape[:-2]
        rotation, position = None, None  # the world rotation (..., 3, 3) and head (..., 3) down the chain
        heads = []
        for k, column in enumerate(columns):
            turn = local[k, :3, :3] if column is None else local[k, :3, :3] @ _rotvec_to_matrix(rotvecs[..., column, :])
            if rotation is None:
                rotation, position = turn.expand(batch + (3, 3)), local[k, :3, 3].expand(batch + (3,))
            else:
                position = position + (rotation @ local[k, :3, 3:])[..., 0]
                rotation = rotation @ turn
            heads.append(position)
        return torch.stack(heads, -2)


def _rotvec_to_matrix(rotvec):
    """(..., 3) rotation vectors -> (..., 3, 3) matrices (Rodrigues), smooth at zero."""
    angle2 = (rotvec * rotvec).sum(-1, keepdim=True)[..., None]  # (..., 1, 1)
    angle = torch.sqrt(angle2 + 1e-12)
    x, y, z = rotvec.unbind(-1)
    zero = torch.zeros_like(x)
    cross = torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], -1).reshape(rotvec.shape[:-1] + (3, 3))
    eye = torch.eye(3, dtype=rotvec.dtype).expand(cross.shape)
    return eye + torch.sin(angle) / angle * cross + (1 - torch.cos(angle)) / (angle2 + 1e-12) * (cross @ cross)


def action_rotvecs(actions, bounds):
    """Actions (..., 45) in [0, 1] -> rotation vectors (..., 15, 3) within the action bounds (45, 2)."""
    low, high = bounds[:, 0], bounds[:, 1]
    return (low + actions * (high - low)).reshape(actions.shape[:-1] + (len(skeleton.ACTION_JOINTS), 3))


def pointing_error(actions, objectives, bounds):
    """(N,) pointing term of actions (N, 45) in [0, 1] against POINT objectives (N, 7): pass only the
    frames that count (the hold), since forward kinematics is most of a training step's cost."""
    rotvecs = action_rotvecs(actions, bounds)
    ray = objectives[..., spaces.OBJECTIVE_ATTRIBUTES]
    error = actions.new_zeros(actions.shape[:-1])
    for k, arm in enumerate(skeleton.ARMS):
        mine = objectives[..., spaces.OBJECTIVE_ARM][..., k] > 0.5  # the frames this arm points on
        if not mine.any():
            continue
        base, finger = FINGERS.finger(rotvecs[mine], arm)
        arm_ray = ray[mine]
        offset = base - torch.as_tensor(skeleton.shoulder_rest_position(arm), dtype=actions.dtype)
        across = offset - (offset * arm_ray).sum(-1, keepdim=True) * arm_ray
        term = (finger - arm_ray).pow(2).sum(-1) + across.pow(2).sum(-1) / REFERENCE_DISTANCE ** 2
        error = error.index_put((mine,), term)
    return error


def wrist_error(actions, motion, objectives, bounds):
    """(N,) squared distance (m^2) between the wrist of actions (N, 45) and of the clip's poses motion
    (N, 45), each frame on its objective's (N, 7) arm: the hand path a wave's swing is measured on."""
    played, reference = action_rotvecs(actions, bounds), action_rotvecs(motion, bounds)
    error = actions.new_zeros(actions.shape[:-1])
    for k, arm in enumerate(skeleton.ARMS):
        mine = objectives[..., spaces.OBJECTIVE_ARM][..., k] > 0.5
        if mine.any():
            with torch.no_grad():  # the clip's wrist is a target
                target = FINGERS.wrist(reference[mine], arm)
            offset = FINGERS.wrist(played[mine], arm) - target
            error = error.index_put((mine,), offset.pow(2).sum(-1))
    return error


_OUTWARD = {"LEFT": 1.0, "RIGHT": -1.0}  # +X is the character's left


def azimuth_elevation(arm, direction):
    """(azimuth, elevation) radians of a unit pointing direction: azimuth 0 ahead, positive out to the
    arm's side, negative across the body; elevation above the horizontal."""
    x, y, z = np.asarray(direction, dtype=np.float64)
    return float(np.arctan2(_OUTWARD[arm] * x, -y)), float(np.arcsin(np.clip(z, -1.0, 1.0)))


def direction_from_angles(arm, azimuth, elevation):
    """The unit pointing direction (3,) of `azimuth_elevation`."""
    return np.array([_OUTWARD[arm] * np.sin(azimuth) * np.cos(elevation), -np.cos(azimuth) * np.cos(elevation),
                     np.sin(elevation)])


def hold_frames(objective, motion_description):
    """(F,) 1.0 where a POINT reference (descriptions (F, 42)) holds its finger on the objective's ray."""
    objective = np.asarray(objective)
    if objective[0, spaces.OBJECTIVE_TYPE] != spaces.BEHAVIOUR_TYPE["POINT"]:
        return np.zeros(len(objective))
    arm = skeleton.ARMS[int(np.argmax(objective[0, spaces.OBJECTIVE_ARM]))]
    side = skeleton.ARMS.index(arm)
    finger = motion_description[:, spaces.DESCRIPTION_EFFECTORS].reshape(-1, 4, 3)[:, 2 + side]
    base = spaces.description_joint_positions(motion_description)[:, 8 + side]
    ray = objective[:, spaces.OBJECTIVE_ATTRIBUTES]
    offset = base - skeleton.shoulder_rest_position(arm)
    across = np.linalg.norm(offset - np.sum(offset * ray, axis=1, keepdims=True) * ray, axis=1)
    angle = np.arccos(np.clip(np.sum(finger * ray, axis=1), -1.0, 1.0))
    return ((angle < HOLD_ANGLE) & (across < HOLD_OFFSET)).astype(np.float64)


#: The canonical skeleton's finger chains, built once.
FINGERS = FingerKinematics()
