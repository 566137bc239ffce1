"""Forward kinematics of action rotations, the numpy FK environment, and the clips' own FK (ClipReferences).

`FKEnvironmentBase` is the environment's interface: `evaluate(action_rotvecs, extra_rotvecs)` and
`describe_actions(actions01, bounds)` -> FKResult, with one input check. Two environments answer it:
trainer/blender_io/fk_env.py (Blender poses the rig: the environment the agent trains in, as the design
says) and NumpyFKEnvironment here (core.kinematics on the canonical skeleton, which the sample rig is
built from: the same numbers without Blender, for fast tests and checks; tests/trainer/blender_io/
test_fk_env.py shows they agree).
"""
from collections import namedtuple
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike

from rlanimate_addon.core import kinematics, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion.clip import MotionClip

#: descriptions (P, 42), joint_positions (P, 10, 3) of skeleton.DESCRIPTION_JOINTS, bone_heads
#: (P, n_bones, 3) in the environment's bone_names order; all in the character frame, metres.
FKResult = namedtuple("FKResult", "descriptions joint_positions bone_heads")

_EYES = ("LeftEye", "RightEye")


def pose_matrices(action_rotvecs: ArrayLike, extra_rotvecs: Mapping[str, ArrayLike] | None = None) -> np.ndarray:
    """(..., B, 4, 4) canonical pose matrices (skeleton.BONE_NAMES order) of action rotations (..., 15, 3)
    and optional {bone name: (..., 3)} rotations of other bones; every other bone stays at rest."""
    rotvecs = np.asarray(action_rotvecs, dtype=np.float64)
    local: dict[str, ArrayLike] = {joint: rotvecs[..., k, :] for k, joint in enumerate(skeleton.ACTION_JOINTS)}
    local.update(extra_rotvecs or {})
    return kinematics.pose_matrices(local)


def bone_heads(action_rotvecs: ArrayLike, extra_rotvecs: Mapping[str, ArrayLike] | None = None) -> np.ndarray:
    """(..., B, 3) head positions, skeleton.BONE_NAMES order, of the pose `pose_matrices` makes."""
    return kinematics.head_positions(pose_matrices(action_rotvecs, extra_rotvecs))


class FKEnvironmentBase:
    """What both FK environments share: input checks, describe_actions, and the FKResult built from the
    bone heads and eye axes a subclass's `_pose(rotvecs)` returns. Subclasses set `bone_names` (the order of
    bone_heads) and `_pose_names` (the order of the rotations `_pose` takes)."""

    bone_names: tuple[str, ...] = ()
    _pose_names: tuple[str, ...] = ()

    def evaluate(self, action_rotvecs: ArrayLike, extra_rotvecs: Mapping[str, ArrayLike] | None = None) -> FKResult:
        """FKResult for P poses.

        action_rotvecs: (P, 15, 3) local rotation vectors of skeleton.ACTION_JOINTS, relative to rest.
        extra_rotvecs: optional {bone name: (P, 3)} for other bones (e.g. fingers); the rest stay at rest.
        """
        heads, eye_axes = self._pose(self._checked(action_rotvecs, extra_rotvecs))  # (P, n_bones, 3), {eye: (P, 3)}
        positions = {name: heads[:, i] for i, name in enumerate(self.bone_names)}
        descriptions = spaces.describe(positions, eye_axes)
        return FKResult(descriptions, spaces.description_joint_positions(descriptions), heads)

    def describe_actions(self, actions01: ArrayLike, bounds: np.ndarray = spaces.DEFAULT_ACTION_BOUNDS) -> FKResult:
        """FKResult for (P, 45) actions in [0, 1], decoded with `bounds` (45, 2) by spaces.decode_action."""
        actions = np.asarray(actions01, dtype=np.float64)
        if actions.ndim != 2 or actions.shape[1] != spaces.ACTION_SIZE:
            raise RLAnimateError(f"Actions must have shape (P, {spaces.ACTION_SIZE}), got {actions.shape}.")
        return self.evaluate(spaces.decode_action(actions, bounds))

    def _checked(self, action_rotvecs, extra_rotvecs):
        """Validate the inputs and return (P, len(_pose_names), 3) rotation vectors in _pose_names order."""
        actions = np.asarray(action_rotvecs, dtype=np.float64)
        joints = len(skeleton.ACTION_JOINTS)
        if actions.ndim != 3 or actions.shape[1:] != (joints, 3):
            raise RLAnimateError(f"Action rotations must have shape (P, {joints}, 3), got {actions.shape}.")
        if not np.all(np.isfinite(actions)):
            raise RLAnimateError("Action rotations contain NaN or infinity: check the agent's output.")
        slots = {name: k for k, name in enumerate(self._pose_names)}
        rotvecs = np.zeros((len(actions), len(self._pose_names), 3))
        rotvecs[:, [slots[j] for j in skeleton.ACTION_JOINTS]] = actions
        for name, values in (extra_rotvecs or {}).items():
            bone = skeleton.strip_prefix(name)
            if bone not in slots:
                raise RLAnimateError(f"The rig has no bone {name!r}: use names of skeleton.BONES.")
            values = np.asarray(values, dtype=np.float64)
            if values.shape != (len(actions), 3):
                raise RLAnimateError(f"Rotations of {name!r} must have shape ({len(actions)}, 3), "
                                     f"got {values.shape}.")
            if not np.all(np.isfinite(values)):
                raise RLAnimateError(f"Rotations of {name!r} contain NaN or infinity.")
            rotvecs[:, slots[bone]] = values
        return rotvecs

    def _pose(self, rotvecs: np.ndarray) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """(bone heads (P, len(bone_names), 3), {eye: (P, 3) its Y axis}) of (P, len(_pose_names), 3) rotations."""
        raise NotImplementedError


class NumpyFKEnvironment(FKEnvironmentBase):
    """The FK environment of the canonical skeleton in numpy (core.kinematics), without Blender."""

    bone_names = skeleton.BONE_NAMES
    _pose_names = skeleton.BONE_NAMES
    _EYE_SLOTS = {eye: skeleton.BONE_NAMES.index(eye) for eye in _EYES}

    def _pose(self, rotvecs):
        pose = kinematics.pose_matrices({name: rotvecs[:, k] for k, name in enumerate(self._pose_names)})
        return kinematics.head_positions(pose), {eye: pose[:, slot, :3, 1] for eye, slot in self._EYE_SLOTS.items()}


class ClipReferences:
    """FK of each clip's own motion (descriptions (F, 42), joint positions (F, 10, 3)), computed once."""

    def __init__(self, env: FKEnvironmentBase):
        self.env = env
        self._cache: dict[int, tuple[MotionClip, np.ndarray, np.ndarray]] = {}

    def get(self, clip: MotionClip) -> tuple[np.ndarray, np.ndarray]:
        key = id(clip)
        if key not in self._cache:
            result = self.env.evaluate(np.asarray(clip.rotvecs, dtype=np.float64))
            self._cache[key] = (clip, np.asarray(result.descriptions), np.asarray(result.joint_positions))
        return self._cache[key][1:]
