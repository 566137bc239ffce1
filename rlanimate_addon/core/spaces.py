"""The paper's spaces (Tables 2 and 3) as named numpy encodings.

Objective o_t (L + 6), laid out by an ObjectiveSpace from the agent's behaviours (core/behaviours.py):
    [label (L), left_arm, right_arm, attr_x, attr_y, attr_z, t/N]
    The label names the behaviour: for at most two behaviours, Table 2's type code (1 for the first,
    2 for the second; L = 1), so point and wave give the paper's 7 numbers; for more, a one-hot over
    them (L = N). The fields after it are addressed from the end, the same for any N. For a target
    behaviour (point), the attributes are the unit vector from the arm's rest shoulder joint to the
    target, in the character frame, so a finger laid along that line from the shoulder passes through
    the target whatever its distance. For an intensity behaviour (wave), they are the exaggeration in
    [0, 1] three times, or, for an oscillating behaviour (wave) with its rhythm, the exaggeration and its rhythm
    [A_t sin(phi_t), A_t cos(phi_t)] (core/rhythm.py). t/N runs over 0..1 (t = 0..N-1, divided by N-1).
Description d_t (42), in the character frame in metres:
    [0:12]  unit effector vectors: left eye, right eye, left index, right index (skeleton.EFFECTORS)
    [12:42] positions of skeleton.DESCRIPTION_JOINTS: collars, shoulders, elbows, wrists, index bases
Action a_t (45): the local rotations of skeleton.ACTION_JOINTS, 3 numbers each, as the exponential
    map (rotation vector, radians) of the pose-bone rotation relative to rest, each mapped to [0, 1]
    by per-channel bounds: a = (r - low) / (high - low).

The character frame is the armature's object space with its scale removed: +X the character's left,
-Y forward, +Z up, origin on the ground between the feet.
"""
from collections.abc import Mapping, Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import behaviours, rhythm, skeleton
from .behaviours import TARGET, Behaviour
from .errors import RLAnimateError

DESCRIPTION_SIZE = 42
ACTION_SIZE = 3 * len(skeleton.ACTION_JOINTS)

#: The objective's fields after its label, the same for any number of behaviours.
OBJECTIVE_ARM = slice(-6, -4)
OBJECTIVE_ATTRIBUTES = slice(-4, -1)
OBJECTIVE_TIME = -1
_FIELDS_AFTER_LABEL = 6

DESCRIPTION_EFFECTORS = slice(0, 12)
DESCRIPTION_POSITIONS = slice(12, 42)

# Per-joint bounds (radians) of each rotation-vector channel, before mapping to [0, 1]. They cover
# the human range of motion measured from the T-pose rest: an arm hangs at about 1.3 rad and
# crosses the body at up to about 2.3 rad from rest; the elbow bends to about 2.5 rad.
_JOINT_BOUNDS = {
    "Spine": 0.5, "Spine1": 0.5, "Spine2": 0.5, "Neck": 0.7, "Head": 0.9,
    "Shoulder": 0.7, "Arm": 2.6, "ForeArm": 2.7, "Hand": 1.4, "HandIndex1": 1.6,
}


def _joint_bound(joint: str) -> float:
    for side in ("Left", "Right"):
        if joint.startswith(side):
            return _JOINT_BOUNDS[joint[len(side):]]
    return _JOINT_BOUNDS[joint]


#: (45, 2) default [low, high] per action channel, in action order.
DEFAULT_ACTION_BOUNDS: npt.NDArray[np.float64] = np.array(
    [[-_joint_bound(j), _joint_bound(j)] for j in skeleton.ACTION_JOINTS for _ in range(3)])


def check_arm_and_length(arm: str, frame_count: int) -> None:
    """RLAnimateError for an unknown arm or a gesture of under 2 frames."""
    if arm not in skeleton.ARMS:
        raise RLAnimateError(f"Unknown arm {arm!r}: use LEFT or RIGHT.")
    if int(frame_count) < 2:
        raise RLAnimateError(f"A gesture needs at least 2 frames, got {frame_count}: set a longer length.")


class ObjectiveSpace:
    """The objective layout of an agent's behaviours (a tuple of core.behaviours.Behaviour, in objective
    order): its size, each behaviour's label, and the objectives of a request."""

    def __init__(self, declared: tuple[Behaviour, ...]) -> None:
        if not declared:
            raise RLAnimateError("An agent needs at least one behaviour.")
        self.behaviours = tuple(declared)
        self.names = tuple(b.name for b in self.behaviours)
        if len(set(self.names)) != len(self.names):
            raise RLAnimateError(f"The behaviours {', '.join(self.names)} name one behaviour twice.")
        self._declared = {b.name: b for b in self.behaviours}
        count = len(self.behaviours)
        #: (N, L) each behaviour's label: Table 2's type code for at most two behaviours, else one-hot.
        self.labels: npt.NDArray[np.float64] = np.arange(1.0, count + 1.0)[:, None] if count <= 2 else np.eye(count)
        self.label_size = self.labels.shape[1]
        self.size = self.label_size + _FIELDS_AFTER_LABEL

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ObjectiveSpace) and self.behaviours == other.behaviours

    def __hash__(self) -> int:
        return hash(self.behaviours)

    def __repr__(self) -> str:
        return f"ObjectiveSpace({', '.join(f'{b.name} {b.kind}' for b in self.behaviours)})"

    def kind(self, behaviour: str) -> str:
        """The kind (behaviours.TARGET or INTENSITY) of the behaviour id `behaviour`."""
        return self.behaviour(behaviour).kind

    def behaviour(self, behaviour: str) -> Behaviour:
        """The declaration (kind, and what it does) of the behaviour id `behaviour`."""
        self.check_behaviour(behaviour)
        return self._declared[behaviour]

    def of_kind(self, kind: str) -> tuple[str, ...]:
        """The ids of the behaviours of `kind`, in objective order."""
        return tuple(b.name for b in self.behaviours if b.kind == kind)

    def oscillating(self) -> tuple[str, ...]:
        """The ids of the behaviours that oscillate (carry a rhythm), in objective order."""
        return tuple(b.name for b in self.behaviours if b.oscillates)

    def check_behaviour(self, behaviour: str) -> None:
        if behaviour not in self._declared:
            raise RLAnimateError(f"Unknown behaviour {behaviour!r}: use one of {', '.join(self.names)}.")

    def check_request(self, behaviour: str, arm: str, frame_count: int) -> None:
        """RLAnimateError naming what no agent or baseline can answer: an unknown behaviour or arm, or
        under 2 frames."""
        self.check_behaviour(behaviour)
        check_arm_and_length(arm, frame_count)

    def label_mask(self, objectives: ArrayLike, behaviour: str) -> npt.NDArray[np.bool_]:
        """(...,) bool: which objectives (..., L + 6) carry the label of `behaviour`."""
        label = self.labels[self.names.index(behaviour)]
        mask: npt.NDArray[np.bool_] = np.all(np.asarray(objectives)[..., :self.label_size] == label, axis=-1)
        return mask

    def kind_mask(self, objectives: ArrayLike, kind: str) -> npt.NDArray[np.bool_]:
        """(...,) bool: which objectives (..., L + 6) belong to a behaviour of `kind`."""
        return self._labels_mask(objectives, self.of_kind(kind))

    def _labels_mask(self, objectives: ArrayLike, names: Sequence[str]) -> npt.NDArray[np.bool_]:
        """(...,) bool: which objectives (..., L + 6) carry the label of one of the behaviours `names`."""
        masks = [self.label_mask(objectives, name) for name in names]
        return np.any(masks, axis=0) if masks else np.zeros(np.shape(objectives)[:-1], dtype=bool)

    def phase_features(self, objectives: ArrayLike, tempo: bool = False) -> npt.NDArray[np.float64]:
        """(..., T, rhythm.PHASE_FEATURES (+ 1 with `tempo`)) of objectives (..., T, L + 6): an oscillating
        behaviour's rhythm signals and their second harmonic (rhythm.phase_features), then with `tempo` its swing
        rate (rhythm.swing_rate); zeros for another behaviour's objectives."""
        objectives = np.asarray(objectives, dtype=np.float64)
        wave = self._labels_mask(objectives, self.oscillating())
        signals = objectives[..., OBJECTIVE_ATTRIBUTES][..., 1:]
        features: npt.NDArray[np.float64] = rhythm.phase_features(signals)
        if tempo:
            features = np.concatenate([features, rhythm.swing_rate(signals)], -1)
        return features * wave[..., None]

    def behaviours_in(self, objectives: ArrayLike) -> set[str]:
        """The ids whose labels the objectives (..., L + 6) carry; RLAnimateError for a label of none."""
        objectives = np.asarray(objectives)
        masks = {name: self.label_mask(objectives, name) for name in self.names}
        if not np.all(np.any(list(masks.values()), axis=0)):
            raise RLAnimateError(f"The objectives carry a behaviour label that is none of {', '.join(self.names)}.")
        return {name for name, mask in masks.items() if mask.any()}

    def make_objective(self, behaviour: str, arm: str, attributes: ArrayLike, frame_count: int,
                       rhythm: ArrayLike | None = None) -> npt.NDArray[np.float64]:
        """(N, L + 6) objectives for a gesture of `frame_count` frames.

        `attributes` is, for a target behaviour, a unit vector (3,) or one per frame (N, 3), so a moving
        target is tracked; for an intensity behaviour, the exaggeration in [0, 1] (scalar or (N,)).
        `rhythm` (N, 2), an oscillating behaviour only: the swing signals of core/rhythm.py; None gives the paper's
        objective (the exaggeration three times).
        """
        self.check_request(behaviour, arm, frame_count)
        n = int(frame_count)
        attrs = np.asarray(attributes, dtype=np.float64)
        if self._declared[behaviour].kind == TARGET:
            attrs = np.broadcast_to(attrs, (n, 3))
            norms = np.linalg.norm(attrs, axis=1, keepdims=True)
            if not np.all(np.isfinite(attrs)) or np.any(norms < 1e-9):
                raise RLAnimateError("The pointing direction is zero or not a number: move the target away "
                                     "from the character's shoulder.")
            attrs = attrs / norms
        else:
            exaggeration = np.broadcast_to(attrs, (n,))
            if not np.all(np.isfinite(exaggeration)) or np.any((exaggeration < 0) | (exaggeration > 1)):
                raise RLAnimateError("Exaggeration must be a number between 0 and 1.")
            attrs = np.repeat(exaggeration[:, None], 3, axis=1)
            if rhythm is not None:
                if not self._declared[behaviour].oscillates:
                    raise RLAnimateError(f"Only an oscillating behaviour (a wave) carries a rhythm in its objective, "
                                         f"not {behaviour}.")
                rhythm = np.asarray(rhythm, dtype=np.float64)
                if rhythm.shape != (n, 2) or not np.all(np.isfinite(rhythm)):
                    raise RLAnimateError(f"The wave rhythm must be finite signals of shape ({n}, 2), got "
                                         f"{rhythm.shape}.")
                attrs[:, 1:] = rhythm
        objective = np.zeros((n, self.size))
        objective[:, :self.label_size] = self.labels[self.names.index(behaviour)]
        objective[:, OBJECTIVE_ARM] = (1.0, 0.0) if arm == "LEFT" else (0.0, 1.0)
        objective[:, OBJECTIVE_ATTRIBUTES] = attrs
        objective[:, OBJECTIVE_TIME] = np.linspace(0.0, 1.0, n)
        return objective


#: Point and wave (Table 2): the space of every agent file that declares no behaviours.
PAPER_SPACE = ObjectiveSpace(behaviours.PAPER)


def pointing_direction(arm: str, target: ArrayLike) -> npt.NDArray[np.float64]:
    """Unit vector (3,) from the arm's rest shoulder joint to `target` (3,), both in the character frame."""
    offset = np.asarray(target, dtype=np.float64) - skeleton.shoulder_rest_position(arm)
    norm = np.linalg.norm(offset)
    if not np.isfinite(norm) or norm < 1e-6:
        raise RLAnimateError("The target sits on the pointing shoulder: move it away from the character.")
    return offset / norm


def encode_action(rotvecs: ArrayLike,
                  bounds: npt.NDArray[np.float64] = DEFAULT_ACTION_BOUNDS) -> npt.NDArray[np.float64]:
    """(..., 15, 3) rotation vectors -> (..., 45) actions in [0, 1] (clipped to the bounds)."""
    flat = np.asarray(rotvecs, dtype=np.float64).reshape(np.shape(rotvecs)[:-2] + (ACTION_SIZE,))
    low, high = bounds[:, 0], bounds[:, 1]
    return np.clip((flat - low) / (high - low), 0.0, 1.0)


def decode_action(action: ArrayLike,
                  bounds: npt.NDArray[np.float64] = DEFAULT_ACTION_BOUNDS) -> npt.NDArray[np.float64]:
    """(..., 45) actions in [0, 1] -> (..., 15, 3) rotation vectors in radians."""
    a = np.asarray(action, dtype=np.float64)
    low, high = bounds[:, 0], bounds[:, 1]
    rot = low + a * (high - low)
    return rot.reshape(a.shape[:-1] + (len(skeleton.ACTION_JOINTS), 3))


def describe(positions: Mapping[str, ArrayLike], eye_axes: Mapping[str, ArrayLike]) -> npt.NDArray[np.float64]:
    """Description (..., 42) from world data in the character frame.

    positions: mapping bone name -> (..., 3) head position in metres (DESCRIPTION_JOINTS, fingertips).
    eye_axes: mapping 'LeftEye'/'RightEye' -> (..., 3) the eye bone's Y axis.
    """
    vectors = []
    for _, start, end in skeleton.EFFECTORS:
        v = eye_axes[start] if end is None else np.asarray(positions[end]) - np.asarray(positions[start])
        v = np.asarray(v, dtype=np.float64)
        vectors.append(v / np.linalg.norm(v, axis=-1, keepdims=True))
    joints = [np.asarray(positions[bone], dtype=np.float64) for _, bone in skeleton.DESCRIPTION_JOINTS]
    return np.concatenate(vectors + joints, axis=-1)


def description_joint_positions(description: ArrayLike) -> npt.NDArray[np.float64]:
    """(..., 42) descriptions -> (..., 10, 3) joint positions, the joints the paper's score compares."""
    d = np.asarray(description)
    return d[..., DESCRIPTION_POSITIONS].reshape(d.shape[:-1] + (len(skeleton.DESCRIPTION_JOINTS), 3))
