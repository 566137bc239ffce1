"""Rigify's generated rigs: their arms' IK-FK switch, and an arm in IK switched to FK for a gesture.

A Rigify arm has FK controls (upper_arm_fk.L, forearm_fk.L, hand_fk.L), IK controls (hand_ik.L and
its pole) and a switch, the IK_FK property of upper_arm_parent.L: 1.0 plays the FK controls, 0.0
the IK ones, and the ORG- bones (ORG-upper_arm.L, ...) and the DEF- bones after them follow the mix.

The gesture keys the FK controls. An arm in IK is switched to FK over the gesture's frames only, and
the FK controls start from the pose the arm has in IK (`snap_fk`: the pose underneath is the IK
pose, so at the gesture's first and last frames FK and IK show the same arm). The switch is keyed
from its own value to 1.0 (a smoothstep) over the first quarter of the gesture's blend in, and back
over the last quarter of its blend out (`switch_values`): while it moves the FK keys are still within a quarter of
their way from the IK pose, so the mix of the two arms (which is not the gesture's own blend) stays
close to both, and the aimed middle of the gesture plays on FK alone.
"""
from collections.abc import Mapping, Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from .gesture import RigState, blend_weights
from .rig import inverse

#: The arm's FK controls, shoulder to hand, without their side (".L", ".R").
FK_CHAIN = ("upper_arm_fk", "forearm_fk", "hand_fk")
SWITCH = "IK_FK"
_SIDES = {"LEFT": ".L", "RIGHT": ".R"}


def switch_bone(arm: str) -> str:
    """The bone holding the arm's IK_FK property."""
    return "upper_arm_parent" + _SIDES[arm]


def fk_controls(arm: str) -> tuple[str, ...]:
    """The arm's FK controls, shoulder to hand."""
    return tuple(name + _SIDES[arm] for name in FK_CHAIN)


def org_bone(control: str) -> str:
    """The ORG- bone an FK control stands for: 'upper_arm_fk.L' -> 'ORG-upper_arm.L'."""
    return "ORG-" + control.replace("_fk", "", 1)


#: The switch reaches FK when the gesture's blend weight reaches this.
SWITCH_AT = 0.25


def switch_values(under: ArrayLike, count: int, blend_type: str, default: float) -> npt.NDArray[np.float64]:
    """(N,) IK_FK keys for a gesture of `count` frames: from the switch's value underneath (N,) to FK
    (1.0) and back (see the module), as a Replace layer keys them, or, for a Combine layer (which adds
    a generic property's key minus its default value to the value underneath), that difference."""
    under = np.broadcast_to(np.asarray(under, dtype=np.float64), (count,))
    rise = np.minimum(1.0, blend_weights(count) / SWITCH_AT)
    # smoothstep: no kink in the hand's speed
    played: npt.NDArray[np.float64] = under + (1.0 - under) * rise * rise * (3.0 - 2.0 * rise)
    return played - under + default if blend_type == "COMBINE" else played


def snap_fk(rig: RigState, controls: Sequence[str], played: Mapping[str, npt.NDArray[np.float64]]) -> RigState:
    """A RigState in which the FK `controls` (role bones, parents first) stand where the arm plays:
    played {control: (N, 4, 4)} the armature-space pose of the bone each stands for (its ORG- bone).

    Each control's new basis turns it onto the played pose from where its (new) parent carries it:
    B' = B P^-1 Q_old Q_new^-1 T (P its pose, Q its role parent's, T the played pose); only its rotation
    is taken (FK controls are keyed by rotation). The bones below the chain (the fingers) follow the
    ORG- bones: they are carried from the played pose to the control's (the same but for an IK stretch).
    """
    count = len(next(iter(played.values())))
    basis, pose = np.array(rig.under_at(count)), np.array(rig.under_pose_at(count))
    new_basis = basis.copy()
    changed, new_pose = [], pose
    for control in controls:
        i = rig.skeleton.index[control]
        parent = rig.skeleton.parents[i]
        carry = np.eye(4) if parent < 0 else pose[:, parent] @ inverse(new_pose[:, parent])  # (N, 4, 4)
        turned = basis[:, i] @ inverse(pose[:, i]) @ carry @ played[control]
        rotation = turned[:, :3, :3] / np.linalg.norm(turned[:, :3, :3], axis=1, keepdims=True)
        new_basis[:, i, :3, :3] = rotation * np.linalg.norm(basis[:, i, :3, :3], axis=1, keepdims=True)
        changed.append(i)
        new_pose = rig.skeleton.pose_after(pose, basis, new_basis, changed, only=controls)
    for i, name in enumerate(rig.skeleton.names):  # below the chain: carried from the ORG- pose to the control's
        above = [k for k in rig.skeleton.ancestors(name)[:-1] if rig.skeleton.names[k] in controls]
        if above and name not in controls:
            control = rig.skeleton.names[above[-1]]
            new_pose[:, i] = new_pose[:, above[-1]] @ inverse(played[control]) @ pose[:, i]
    snapped: RigState = rig.with_pose(new_basis, new_pose)
    return snapped
