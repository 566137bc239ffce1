"""Differentiable forward kinematics of the canonical skeleton's arms, in torch (core/kinematics.py in numpy).

The pointing term (trainer/agent/pointing.py) reads the finger line of the animation model's mean
pose, and the wrist term (trainer/agent/losses.py) its wrist.
"""
import numpy as np
import torch

from rlanimate_addon.core import kinematics, skeleton, spaces

_REST = skeleton.rest_matrices()
#: The index finger's bones below the hand (HandIndex1-4), the end of each chain.
_FINGER_BONES = 4


def _chain(arm):
    """Bone indices from the root to the arm's index fingertip (HandIndex4), parents first."""
    index = kinematics.bone_index(skeleton.ARM_PREFIX[arm] + "HandIndex4")
    chain = []
    while index >= 0:
        chain.append(index)
        parent = skeleton.BONES[index].parent
        index = -1 if parent is None else kinematics.bone_index(parent)
    return chain[::-1]


class ArmKinematics:
    """Differentiable heads of each arm's chain, its wrist, finger base and direction, from action rotation
    vectors."""

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
        base, tip = heads[..., -_FINGER_BONES, :], heads[..., -1, :]  # HandIndex1 and HandIndex4 heads
        direction = tip - base
        return base, direction / direction.norm(dim=-1, keepdim=True)

    def wrist(self, rotvecs, arm):
        """rotvecs (..., 15, 3) -> the arm's wrist (its Hand bone's head) (..., 3)."""
        return self.heads(rotvecs, arm, _FINGER_BONES)[..., -1, :]

    def heads(self, rotvecs, arm, skip=0):
        """rotvecs (..., 15, 3) -> the heads (..., K, 3) of the K bones from the root to the index tip, less
        the last `skip` (a head depends only on the bones above it)."""
        local, columns = self._chains[arm]
        local, columns = local[:len(columns) - skip].to(rotvecs.dtype), columns[:len(columns) - skip]
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


def on_each_arm(objectives, frame_error):
    """(N,) frame_error(arm, mask) (a (M,) tensor for the M frames of mask) put on the frames whose
    objective (N, 7) names that arm; 0 elsewhere."""
    error = objectives.new_zeros(objectives.shape[:-1])
    for k, arm in enumerate(skeleton.ARMS):
        mine = objectives[..., spaces.OBJECTIVE_ARM][..., k] > 0.5
        if mine.any():
            error = error.index_put((mine,), frame_error(arm, mine))
    return error


#: The canonical skeleton's arm chains, built once.
ARMS = ArmKinematics()
