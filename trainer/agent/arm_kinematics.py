"""Differentiable forward kinematics of the canonical skeleton's arms, in torch (core/kinematics.py in numpy).

The pointing term (trainer/agent/pointing.py) reads the finger line of the animation model's mean
pose, and the wrist term (trainer/agent/losses.py) its wrist. Each frame is posed on its own arm, both
arms in one pass: the training step runs this on every pointing-hold and waving frame, and its cost is
the number of torch calls, not their arithmetic.
"""
import numpy as np
import torch
from torch import Tensor

from rlanimate_addon.core import kinematics, skeleton, spaces

_REST = skeleton.rest_matrices()
#: The index finger's bones below the hand (HandIndex1-4), the end of each chain.
_FINGER_BONES = 4


def _chain(arm: str) -> list[int]:
    """Bone indices from the root to the arm's index fingertip (HandIndex4), parents first."""
    index = kinematics.bone_index(skeleton.ARM_PREFIX[arm] + "HandIndex4")
    chain = []
    while index >= 0:
        chain.append(index)
        parent = skeleton.BONES[index].parent
        index = -1 if parent is None else kinematics.bone_index(parent)
    return chain[::-1]


def arm_indices(objectives: Tensor) -> Tensor:
    """(N,) long: the arm, as its index in skeleton.ARMS, that each objective (N, O) names."""
    return objectives[..., spaces.OBJECTIVE_ARM].argmax(-1)


class ArmKinematics:
    """Differentiable wrist, finger base and finger direction of either arm from action rotation vectors.

    The two arms' chains (root to index fingertip) have the same shape: K bones, the same of them turned
    by an action joint. The bones past the index base (HandIndex2-4) are fixed, so the fingertip is a
    fixed offset in the index base's frame. A pass gathers each frame's chain, makes all its joints'
    rotations in one batched call (Rodrigues), then composes them down the chain.
    """

    def __init__(self) -> None:
        locals_: list[list[np.ndarray]] = []
        columns: list[list[int | None]] = []
        for arm in skeleton.ARMS:
            chain = _chain(arm)
            locals_.append([_REST[i] if k == 0 else np.linalg.inv(_REST[chain[k - 1]]) @ _REST[i]
                            for k, i in enumerate(chain)])  # each bone in its parent's rest frame
            columns.append([skeleton.ACTION_JOINTS.index(skeleton.BONES[i].name)
                            if skeleton.BONES[i].name in skeleton.ACTION_JOINTS else None for i in chain])
        local = np.array(locals_)  # (2, K, 4, 4)
        #: The chain positions an action joint turns, the same on both arms.
        self.turning = [k for k, column in enumerate(columns[0]) if column is not None]
        #: HandIndex1's position in the chain: the index base.
        self.base = local.shape[1] - _FINGER_BONES
        if any([k for k, column in enumerate(side) if column is not None] != self.turning for side in columns) \
                or self.turning[-1] != self.base:
            raise ValueError("the arms' chains must turn at the same bones, the last being HandIndex1")
        self._rotations = torch.as_tensor(local[:, :, :3, :3])  # (2, K, 3, 3), float64
        self._offsets = torch.as_tensor(local[:, :, :3, 3])  # (2, K, 3)
        self._columns = torch.as_tensor([[side[k] for k in self.turning] for side in columns])  # (2, R)
        tips = []
        for side in local:  # the fingertip in HandIndex1's frame, from HandIndex4 back up
            tip = np.zeros(3)
            for k in range(len(side) - 1, self.base, -1):
                tip = side[k, :3, 3] + side[k, :3, :3] @ tip
            tips.append(tip / np.linalg.norm(tip))
        self._tips = torch.as_tensor(np.array(tips))  # (2, 3) unit

    def finger(self, rotvecs: Tensor, arms: Tensor) -> tuple[Tensor, Tensor]:
        """rotvecs (N, 15, 3), arms (N,) (indices in skeleton.ARMS) -> each frame's index base (N, 3) and unit
        finger direction (N, 3)."""
        rotation, base = self._down_chain(rotvecs, arms, self.base, with_rotation=True)
        assert rotation is not None  # asked for
        return base, (rotation @ self._tips.to(rotvecs.dtype)[arms, :, None])[..., 0]

    def wrist(self, rotvecs: Tensor, arms: Tensor) -> Tensor:
        """rotvecs (N, 15, 3), arms (N,) -> each frame's wrist (its arm's Hand bone's head) (N, 3)."""
        return self._down_chain(rotvecs, arms, self.base - 1, with_rotation=False)[1]

    def _down_chain(self, rotvecs: Tensor, arms: Tensor, last: int,
                    with_rotation: bool) -> tuple[Tensor | None, Tensor]:
        """(world rotation (N, 3, 3) or None, head (N, 3)) of chain bone `last` of each frame's arm; the
        rotation includes the bone's own turn."""
        rest = self._rotations.to(rotvecs.dtype)[arms]  # (N, K, 3, 3)
        offsets = self._offsets.to(rotvecs.dtype)[arms]  # (N, K, 3)
        columns = self._columns[arms]  # (N, R)
        joints = torch.gather(rotvecs, 1, columns[..., None].expand(-1, -1, 3))  # (N, R, 3)
        turns = dict(zip(self.turning, (rest[:, self.turning] @ _rotvec_to_matrix(joints)).unbind(1), strict=True))
        rotation, position = turns.get(0, rest[:, 0]), offsets[:, 0]
        for k in range(1, last + 1):
            position = position + (rotation @ offsets[:, k, :, None])[..., 0]
            if k < last or with_rotation:
                rotation = rotation @ turns.get(k, rest[:, k])
        return (rotation if with_rotation else None), position


def _rotvec_to_matrix(rotvec: Tensor) -> Tensor:
    """(..., 3) rotation vectors -> (..., 3, 3) matrices (Rodrigues), smooth at zero."""
    angle2 = (rotvec * rotvec).sum(-1, keepdim=True)[..., None]  # (..., 1, 1)
    angle = torch.sqrt(angle2 + 1e-12)
    x, y, z = rotvec.unbind(-1)
    zero = torch.zeros_like(x)
    cross = torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], -1).reshape(rotvec.shape[:-1] + (3, 3))
    eye = torch.eye(3, dtype=rotvec.dtype).expand(cross.shape)
    return eye + torch.sin(angle) / angle * cross + (1 - torch.cos(angle)) / (angle2 + 1e-12) * (cross @ cross)


def action_rotvecs(actions: Tensor, bounds: Tensor) -> Tensor:
    """Actions (..., 45) in [0, 1] -> rotation vectors (..., 15, 3) within the action bounds (45, 2)."""
    low, high = bounds[:, 0], bounds[:, 1]
    return (low + actions * (high - low)).reshape(actions.shape[:-1] + (len(skeleton.ACTION_JOINTS), 3))


#: The canonical skeleton's arm chains, built once.
ARMS = ArmKinematics()
