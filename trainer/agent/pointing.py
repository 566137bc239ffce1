"""The pointing term: how far the agent's own finger line misses the objective's ray, in torch.

The pointing contract (docs/CLIPS.md): at the hold, the index base lies on the ray from the
pointing arm's rest shoulder along the objective's unit vector u, and the finger runs along it, so
the finger's line passes through the target at any distance. Forward kinematics of the canonical
skeleton (trainer/agent/arm_kinematics.py) turns the animation model's mean pose into the finger
base b and unit direction f; the term per frame is

    |f - u|^2 + |(b - S) - ((b - S) . u) u|^2 / REFERENCE_DISTANCE^2

(the squared angle between finger and ray, plus the base's squared offset from the ray seen from a
target REFERENCE_DISTANCE away), averaged over the frames the reference clip holds its point.
"""
import numpy as np
import torch

from rlanimate_addon.core import skeleton, spaces
from trainer.agent.arm_kinematics import ARMS, action_rotvecs, arm_indices

#: Metres: the nearest target distance the agent is asked to hit (targets are 1.5-4 m away).
REFERENCE_DISTANCE = 1.5
#: A reference frame holds its point when its finger is this close to the ray (radians, metres).
HOLD_ANGLE, HOLD_OFFSET = np.radians(1.0), 0.01


def pointing_error(actions, objectives, bounds):
    """(N,) pointing term of actions (N, 45) in [0, 1] against target objectives (N, O), each frame on its
    objective's arm: pass only the frames that count (the hold), since forward kinematics is most of a
    training step's cost."""
    arms = arm_indices(objectives)
    base, finger = ARMS.finger(action_rotvecs(actions, bounds), arms)
    ray = objectives[..., spaces.OBJECTIVE_ATTRIBUTES]
    offset = base - _SHOULDERS.to(actions.dtype)[arms]
    across = offset - (offset * ray).sum(-1, keepdim=True) * ray
    return (finger - ray).pow(2).sum(-1) + across.pow(2).sum(-1) / REFERENCE_DISTANCE ** 2


#: The rest shoulder (2, 3) of each arm (skeleton.ARMS order), where its pointing rays start.
_SHOULDERS = torch.as_tensor(np.array([skeleton.shoulder_rest_position(arm) for arm in skeleton.ARMS]))

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
    """(F,) 1.0 where the reference of a target behaviour's objective (F, O) (its descriptions (F, 42))
    holds its index finger on the objective's ray."""
    objective = np.asarray(objective)
    arm = skeleton.ARMS[int(np.argmax(objective[0, spaces.OBJECTIVE_ARM]))]
    side = skeleton.ARMS.index(arm)
    finger = motion_description[:, spaces.DESCRIPTION_EFFECTORS].reshape(-1, 4, 3)[:, 2 + side]
    base = spaces.description_joint_positions(motion_description)[:, 8 + side]
    ray = objective[:, spaces.OBJECTIVE_ATTRIBUTES]
    offset = base - skeleton.shoulder_rest_position(arm)
    across = np.linalg.norm(offset - np.sum(offset * ray, axis=1, keepdims=True) * ray, axis=1)
    angle = np.arccos(np.clip(np.sum(finger * ray, axis=1), -1.0, 1.0))
    return ((angle < HOLD_ANGLE) & (across < HOLD_OFFSET)).astype(np.float64)
