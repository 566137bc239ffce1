"""From a gesture request to per-frame local bone rotations on a user's rig, in plain numpy.

The pipeline Generate Gesture runs, with Blender only at its two ends (reading the rig, its animation
and the target, writing keys):

    targets (N, 3) in the rig's armature space --pointing_directions--> objectives (N, 7)
    --agent.rollout--> actions (M, 45) --decode, time_scale--> canonical rotations (N, 15, 3)
    --fold_missing, retarget--> rig quaternions (N, D, 4) --blend with the pose underneath-->
    --aim_rig (a pointing behaviour, exact aim)--> keys

A rig may differ from the canonical skeleton in many ways, all handled here:
  * bone names: core.rig_roles maps roles (canonical names) to its bones; a role it lacks is left
    out (the other arm, fingers, eyes), or, for the spine and a collar, folded into the spine bones and
    the upper arm it has;
  * scale and units (a Mixamo FBX in centimetres): only directions and rotations are used;
  * the orientation of its armature space (an FBX whose armature space is Y-up): `character_frame`
    finds the rotation from the rig's armature space to the character frame (+X left, -Y forward,
    +Z up) from its own rest joints;
  * its bones' rest frames (rolls, directions): `retarget_matrices` gives C per bone with
    C = F_can^-1 A F_rig (F: armature-space rest rotations, A: armature -> character frame), and
    the rig's local rotation is R_rig = C^-1 R_can C, which gives every bone the same armature-space
    rotation from rest as on the canonical skeleton;
  * its own animation: the gesture blends in from and out to the pose underneath, frame by frame,
    and Point's aim is solved on the rig's own bones against that pose (`aim_rig`), so the finger
    line passes through the target whatever the rig's proportions and whatever moves underneath.
"""
import math
from collections.abc import Callable, Collection, Container, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import aim, behaviours, frame_rate, rig_roles, skeleton, spaces
from .errors import RLAnimateError
from .rig import RigSkeleton, each_frame, inverse
from .rotations import (
    continuous,
    matrix_to_quat,
    matrix_to_rotvec,
    quat_multiply,
    quat_to_matrix,
    quat_to_rotvec,
    rotation_part,
    rotvec_to_matrix,
    rotvec_to_quat,
)

#: A float64 array: positions, rotations (vectors, quaternions, matrices) and weights, per frame and bone.
Array = npt.NDArray[np.float64]

#: Lengths the agent supports, as fractions of its learned average length (paper Section 4.4).
SUPPORTED_LENGTH = (0.4, 1.5)
#: Fraction of the gesture spent blending in from, and back out to, the rig's pose at the start frame.
BLEND_FRACTION = 0.2

#: Bones of the pointing hand shape, with their canonical local rotation vectors (radians): the
#: thumb tucked, the three other fingers curled towards the palm (negative about the local X axis
#: curls a finger of either hand towards the palm of the T-pose) and the index straight beyond its
#: base (Index1 is the agent's), whatever curl the rig's fingers rest in.
_CURL = {"1": 1.2, "2": 1.4, "3": 1.0}
POINTING_HAND = {
    **{f"{finger}{k}": (-angle, 0.0, 0.0)
       for finger in ("HandMiddle", "HandRing", "HandPinky") for k, angle in _CURL.items()},
    "HandThumb1": (-0.35, 0.0, 0.25), "HandThumb2": (-0.5, 0.0, 0.0), "HandThumb3": (-0.4, 0.0, 0.0),
    "HandIndex2": (0.0, 0.0, 0.0), "HandIndex3": (0.0, 0.0, 0.0),
}


class Agent(Protocol):
    """What the pipeline asks of an agent: core.runtime.GestureAgent, or a stand-in that plays given actions."""

    space: spaces.ObjectiveSpace
    action_bounds: Array  # (45, 2)

    @property
    def average_frames(self) -> Mapping[str, float]: ...

    @property
    def still_free_arm(self) -> Collection[str]: ...

    def kind(self, behaviour: str) -> str: ...

    def rollout(self, objectives: ArrayLike, seed: int | None = None) -> Array: ...

    def wave_rhythm(self, exaggeration: float, frame_count: int, seed: int | None = None,
                    tempo: float | None = None, arm: str | None = None) -> Array | None: ...


#: The shortest gesture that moves: the first and last frames are the start pose (`blend_weights`).
MIN_FRAMES = 3


def check_length(frame_count: int) -> None:
    """RLAnimateError for a gesture too short to move."""
    if int(frame_count) < MIN_FRAMES:
        raise RLAnimateError(f"The gesture is {int(frame_count)} frames long: it starts and ends at the pose of "
                             f"its start frame, so nothing would move. Set a length of at least {MIN_FRAMES} frames.")


def supported_length_range(average_frames: float) -> tuple[int, int]:
    """(shortest, longest) gesture length in frames the agent portrays without visible artefacts."""
    low, high = SUPPORTED_LENGTH
    return max(2, int(round(low * average_frames))), max(2, int(round(high * average_frames)))


#: How length_warning's notes begin (the operator reports a summary holding one as a warning).
LENGTH_WARNING = "warning:"


def length_warning(frame_count: int, average_frames: float) -> str:
    """A note for a gesture shorter than the agent's supported range (its gesture squeezed into so few frames
    that it is rushed), else ""."""
    shortest, longest = supported_length_range(average_frames)
    if int(frame_count) >= shortest:
        return ""
    return (f" ({LENGTH_WARNING} {int(frame_count)} frames is below the agent's supported {shortest}-{longest}, "
            f"so the gesture is rushed; set Frames to {shortest} or more)")


#: Rest joints that fix a rig's orientation: the torso and the shoulders (those the rig has).
_ORIENTATION_BONES = ("Hips", "Spine", "Spine1", "Spine2", "Neck", "Head",
                      "LeftShoulder", "RightShoulder", "LeftArm", "RightArm")


def character_frame(rest_heads: Mapping[str, ArrayLike]) -> Array:
    """(3, 3) rotation A taking vectors in a rig's armature space to the character frame.

    rest_heads: mapping of role -> rest head (3,) in the rig's armature space. A is the rotation that
    best lays the rig's torso and shoulder joints onto the canonical ones (Kabsch), so it ignores the
    rig's units and proportions; the character frame has +X left, -Y forward, +Z up.
    """
    names = [name for name in _ORIENTATION_BONES if name in rest_heads]
    rig = np.array([rest_heads[name] for name in names], dtype=np.float64)  # (J, 3)
    canonical = np.array([skeleton.BONE_BY_NAME[name].head for name in names])
    rig, canonical = rig - rig.mean(axis=0), canonical - canonical.mean(axis=0)
    u, _, vt = np.linalg.svd(canonical.T @ rig)
    sign = np.sign(np.linalg.det(u @ vt))
    rotation: Array = u @ np.diag([1.0, 1.0, sign]) @ vt
    return rotation


#: A target nearer the rest shoulder than this times the arm's reach is refused: the collar bone's turn
#: carries the finger base past the rest reach (the sample rig's arm points away from a target 1.04
#: times the reach in front of its shoulder, and hits one at 1.09).
REACH_MARGIN = 1.1


def check_finite_targets(targets: ArrayLike) -> None:
    """RLAnimateError when any target (N, 3) is not a number."""
    broken = ~np.isfinite(np.atleast_2d(targets)).all(axis=1)
    if np.any(broken):
        raise RLAnimateError(f"The target's position is not a number (NaN or infinite) on {broken.sum()} of the "
                             f"gesture's {len(broken)} frames: check the target's location, constraints, drivers "
                             "and parents, and the armature's transform.")


def pointing_directions(arm: str, targets: ArrayLike, rest_heads: Mapping[str, ArrayLike]) -> Array:
    """(N, 3) unit vectors in the character frame from the rig's rest shoulder to each target.

    targets: (N, 3) target positions in the rig's armature space (any units, the rig's own).
    """
    shoulder = np.asarray(rest_heads[skeleton.ARM_PREFIX[arm] + "Arm"], dtype=np.float64)
    offsets = np.atleast_2d(np.asarray(targets, dtype=np.float64)) - shoulder  # (N, 3)
    norms = np.linalg.norm(offsets, axis=1)
    scale = np.linalg.norm(np.subtract(rest_heads["Head"], shoulder))
    check_finite_targets(targets)
    if np.any(norms < 1e-3 * scale):
        raise RLAnimateError("The target sits on the pointing shoulder: move it away from the character.")
    reach = arm_reach(arm, rest_heads)
    if np.any(norms < REACH_MARGIN * reach):
        raise RLAnimateError(f"The target comes within the {arm.lower()} arm's reach (at its closest "
                             f"{norms.min() / reach:.0%} of the way from the shoulder to the outstretched index "
                             "finger), so the pointing arm would reach through it and point away from it: move the "
                             f"target at least {REACH_MARGIN:.1f} times that far from the shoulder.")
    directions: Array = (offsets / norms[:, None]) @ character_frame(rest_heads).T
    return directions


def arm_reach(arm: str, rest_heads: Mapping[str, ArrayLike]) -> float:
    """The outstretched arm's reach: from the rest shoulder to the index finger's base, in the rig's
    units (rest_heads: {role: (3,)}); from the wrist, scaled as on the canonical skeleton, for a rig
    without index bones."""
    prefix = skeleton.ARM_PREFIX[arm]
    shoulder = np.asarray(rest_heads[prefix + "Arm"], dtype=np.float64)
    if prefix + "HandIndex1" in rest_heads:
        return float(np.linalg.norm(np.subtract(rest_heads[prefix + "HandIndex1"], shoulder)))
    canonical = {name: np.asarray(skeleton.BONE_BY_NAME[prefix + name].head) for name in ("Arm", "Hand", "HandIndex1")}
    ratio = np.linalg.norm(canonical["HandIndex1"] - canonical["Arm"]) / np.linalg.norm(
        canonical["Hand"] - canonical["Arm"]
    )
    return float(ratio * np.linalg.norm(np.subtract(rest_heads[prefix + "Hand"], shoulder)))


def build_objectives(space: spaces.ObjectiveSpace, behaviour: str, arm: str, frame_count: int, *,
                     targets: ArrayLike | None = None, rest_heads: Mapping[str, ArrayLike] | None = None,
                     exaggeration: float = 0.5, rhythm: ArrayLike | None = None) -> Array:
    """(N, O) objectives of the ObjectiveSpace `space` for a gesture: a target behaviour needs targets
    (N, 3) and rest_heads; an intensity behaviour an exaggeration and, for an oscillating one (a wave) from an
    agent trained with them, rhythm signals (N, 2) (GestureAgent.wave_rhythm)."""
    check_length(frame_count)
    if space.kind(behaviour) == behaviours.TARGET:
        if targets is None:
            raise RLAnimateError(f"{behaviours.title(behaviour)} needs a target: pick a target object, or tick "
                                 "'Use 3D Cursor'.")
        assert rest_heads is not None, "a target behaviour's objectives need the rig's rest_heads"
        attributes: ArrayLike = pointing_directions(arm, targets, rest_heads)
    else:
        attributes = exaggeration
    return space.make_objective(behaviour, arm, attributes, frame_count,
                                rhythm if space.behaviour(behaviour).oscillates else None)


def resample(values: ArrayLike, count: int) -> Array:
    """Linear resampling of (M, ...) values along the first axis to (count, ...), ends kept."""
    values = np.asarray(values, dtype=np.float64)
    if len(values) == count:
        return values.copy()
    position = np.linspace(0.0, len(values) - 1, count)
    low = np.floor(position).astype(int)
    high = np.minimum(low + 1, len(values) - 1)
    frac = (position - low).reshape((-1,) + (1,) * (values.ndim - 1))
    resampled: Array = values[low] * (1.0 - frac) + values[high] * frac
    return resampled


def rollout_length(frame_count: int, average_frames: float, kind: str) -> int:
    """Steps the agent runs for a gesture of frame_count frames: clamped into its supported range, and
    for a target behaviour (`kind`) never fewer than the agent's average. A shorter point is the
    average-length point played faster: the agent's own quick points hold for a few frames and miss by
    more (docs/EXTENSION.md, "Short points")."""
    shortest, longest = supported_length_range(average_frames)
    if kind == behaviours.TARGET:
        shortest = max(shortest, int(round(average_frames)))
    return int(np.clip(frame_count, shortest, longest))


def run_agent(agent: Agent, behaviour: str, objectives: Array, seed: int | None = None,
              frame_count: int | None = None) -> Array:
    """Canonical local rotation vectors (N, 15, 3) for the objectives (M, O) at the agent's rate.

    The agent runs for `rollout_length(M)` steps; its actions are resampled to the N = frame_count
    scene frames (M when None) when that differs (time-scaled, or played at the scene's rate).
    """
    count = len(objectives) if frame_count is None else int(frame_count)
    kind = agent.kind(behaviour)
    steps = rollout_length(len(objectives), agent.average_frames[behaviour], kind)
    agent_objectives = resample(objectives, steps)
    agent_objectives[:, spaces.OBJECTIVE_TIME] = np.linspace(0.0, 1.0, steps)
    if kind == behaviours.TARGET:
        attrs = agent_objectives[:, spaces.OBJECTIVE_ATTRIBUTES]
        agent_objectives[:, spaces.OBJECTIVE_ATTRIBUTES] = attrs / np.linalg.norm(attrs, axis=1, keepdims=True)
    actions = np.asarray(agent.rollout(agent_objectives, seed=seed), dtype=np.float64)  # (steps, 45)
    if actions.shape != (steps, spaces.ACTION_SIZE) or not np.all(np.isfinite(actions)):
        raise RLAnimateError(f"The agent returned actions of shape {actions.shape} or non-finite values: "
                             "choose another agent file in the add-on preferences.")
    return spaces.decode_action(resample(actions, count), np.asarray(agent.action_bounds))


_CANONICAL_FRAMES = {bone.name: skeleton.rest_frame(bone) for bone in skeleton.BONES}


def retarget_matrices(canonical_bones: Iterable[str], rig_rest_frames: ArrayLike, to_character: Array,
                      swings: Array | None = None) -> Array:
    """(B, 3, 3) C = F_can^-1 D A F_rig for each named canonical bone.

    rig_rest_frames: (B, 3, 3) armature-space rest rotations of the rig's bones (columns: local axes).
    swings: (B, 3, 3) D, character-frame rotations that lay each rig bone's rest direction onto the
    canonical one (`rest_swings`; identity when None).
    """
    canonical = np.stack([_CANONICAL_FRAMES[name] for name in canonical_bones])
    frames = to_character @ np.asarray(rig_rest_frames, dtype=np.float64)
    if swings is not None:
        frames = swings @ frames
    return np.swapaxes(canonical, -1, -2) @ frames


def retarget(canonical_rotvecs: ArrayLike, conversions: Array, parent_conversions: Array | None = None) -> Array:
    """Canonical local rotation vectors (..., B, 3) -> the rig's local quaternions (..., B, 4).

    R_rig = P^-1 R_can C per bone, with C from `retarget_matrices` and P the same built with the
    parent's swing (P = C when the rig rests like the canonical T-pose).
    """
    rotations = rotvec_to_matrix(canonical_rotvecs)  # (..., B, 3, 3)
    left = conversions if parent_conversions is None else parent_conversions
    return matrix_to_quat(np.swapaxes(left, -1, -2) @ rotations @ conversions)


_FINGERS = ("Thumb", "Index", "Middle", "Ring", "Pinky")
#: Role whose rest head a bone's rest direction points to, for the bones whose rest pose differs
#: between rigs (T- or A-pose arms, relaxed or straight fingers); the spine, neck and head rest upright.
_DIRECTION_TO = {f"{side}{bone}": f"{side}{child}" for side in ("Left", "Right")
                 for bone, child in (("Shoulder", "Arm"), ("Arm", "ForeArm"), ("ForeArm", "Hand"),
                                     ("Hand", "HandMiddle1"))
                 + tuple((f"Hand{finger}{k}", f"Hand{finger}{k + 1}") for finger in _FINGERS for k in (1, 2, 3))}
#: The canonical skeleton's rest direction (3,) of each bone in _DIRECTION_TO.
_CANONICAL_DIRECTIONS = {name: np.subtract(skeleton.BONE_BY_NAME[child].head, skeleton.BONE_BY_NAME[name].head)
                         for name, child in _DIRECTION_TO.items()}
#: Each finger's last posable bone: without the end bone after it, its direction comes from its tail.
_FINGER_LAST = {f"{side}Hand{finger}3" for side in ("Left", "Right") for finger in _FINGERS}
#: A finger's last bone follows its own tail (when the rig has no fourth bone) only within this many
#: degrees of the bone before it: an imported rig's tails need not run along the finger.
_TAIL_TRUST_DEG = 45.0


def _rest_direction(name: str, rest_heads: Mapping[str, ArrayLike],
                    rest_tails: Mapping[str, ArrayLike]) -> Array | None:
    """(3,) the rig's rest direction of role `name` (armature space), or None: towards the head of the
    role it points to, else, for a finger's last bone, along its own tail while that continues the
    finger (within _TAIL_TRUST_DEG of the bone before it)."""
    child = _DIRECTION_TO.get(name)
    if child is None or name not in rest_heads:
        return None
    if child in rest_heads:
        return np.subtract(rest_heads[child], rest_heads[name])
    before = skeleton.BONE_BY_NAME[name].parent
    if name not in _FINGER_LAST or name not in rest_tails or before is None or before not in rest_heads:
        return None
    own, previous = np.subtract(rest_tails[name], rest_heads[name]), np.subtract(rest_heads[name], rest_heads[before])
    cos = own @ previous / (np.linalg.norm(own) * np.linalg.norm(previous))
    return own if cos >= np.cos(np.radians(_TAIL_TRUST_DEG)) else None


def rest_swings(roles: Container[str], rest_heads: Mapping[str, ArrayLike], rest_tails: Mapping[str, ArrayLike],
                to_character: ArrayLike) -> dict[str, Array]:
    """{role: (3, 3)} D per role: the shortest rotation (character frame) taking the rig's rest
    direction of the bone onto the canonical one. Bones without a direction of their own (the spine,
    a finger's last bone whose tail does not follow the finger) take their parent's (identity at the
    root).

    rest_heads, rest_tails: {role: (3,)} in the rig's armature space. With the swings an A-pose rig
    plays the canonical rotations as a T-pose rig does: the arms hang, raise and wave where the
    canonical skeleton's do, not 45 degrees lower, and a rig whose fingers rest curled points with a
    straight index finger.
    """
    names = [n for n in skeleton.BONE_NAMES if n in roles]  # parents first
    directions = {n: _rest_direction(n, rest_heads, rest_tails) for n in names}
    directed = [n for n in names if directions[n] is not None]
    rig = np.array([directions[n] for n in directed]).reshape(-1, 3) @ np.asarray(to_character).T
    canonical = np.array([_CANONICAL_DIRECTIONS[n] for n in directed]).reshape(-1, 3)
    turns = dict(
        zip(
            directed,
            aim.rotation_between(
                rig / np.linalg.norm(rig, axis=1, keepdims=True),
                canonical / np.linalg.norm(canonical, axis=1, keepdims=True),
            ),
            strict=True,
        )
    )
    swings: dict[str, Array] = {}
    for name in names:
        parent = _parent_role(name, roles)
        swings[name] = turns.get(name, np.eye(3) if parent is None else swings[parent])
    return swings


def _parent_role(name: str, present: Container[str]) -> str | None:
    parent = skeleton.BONE_BY_NAME[name].parent
    while parent is not None and parent not in present:
        parent = skeleton.BONE_BY_NAME[parent].parent
    return parent


#: Chains of action joints, parents first, in which a joint the rig lacks is folded into one it has: the
#: spine, and each collar into its upper arm (an arm hanging from the spine with no collar bone).
FOLDED_CHAINS = (rig_roles.SPINE, ("LeftShoulder", "LeftArm"), ("RightShoulder", "RightArm"))


def fold_missing(rotvecs: Array, joints: Sequence[str], present: Container[str]) -> tuple[list[str], Array]:
    """Canonical rotations (N, J, 3) of `joints` with each joint of a FOLDED_CHAINS chain the rig lacks
    folded into one of that chain it has.

    A missing joint goes to the nearest present one below it (above it when none is below); a present
    joint then turns by the product of its group's armature-space turns, so everything above the chain
    ends up turned as on the canonical skeleton (the neck for the spine, the upper arm for a collar).
    Returns (joints kept, rotations).
    """
    out = rotvecs.copy()
    rotations = rotvec_to_matrix(rotvecs)  # (N, J, 3, 3), each as it would be converted alone
    keepers: list[int] = []
    turns: list[Array] = []
    for chain in FOLDED_CHAINS:
        have = [j for j in chain if j in present]
        if not have:  # an arm the rig lacks
            continue
        groups: dict[str, list[str]] = {j: [] for j in have}
        for j in chain:
            below = [p for p in have if chain.index(p) <= chain.index(j)]
            groups[below[-1] if below else have[0]].append(j)
        for keeper, members in groups.items():
            turn = np.eye(3)
            for j in members:  # chain order: parents first
                frame = _CANONICAL_FRAMES[j]
                turn = turn @ frame @ np.ascontiguousarray(rotations[:, joints.index(j)]) @ frame.T
            frame = _CANONICAL_FRAMES[keeper]
            keepers.append(joints.index(keeper))
            turns.append(frame.T @ turn @ frame)
    if keepers:
        out[:, keepers] = matrix_to_rotvec(np.stack(turns, axis=1))
    kept = [i for i, j in enumerate(joints) if j in present]
    return [joints[i] for i in kept], out[:, kept]


def blend_ramp(count: int, fraction: float = BLEND_FRACTION) -> int:
    """Frames of each of `blend_weights`' ramps for a gesture of `count` frames."""
    return max(1, int(round(fraction * (count - 1))))


def blend_weights(count: int, fraction: float = BLEND_FRACTION) -> Array:
    """(count,) weights of the gesture against the pose underneath: 0 at both ends, 1 in the middle.

    Smoothstep ramps over `fraction` of the frames at each end keep velocity continuous.
    """
    ramp = blend_ramp(count, fraction)
    t = np.arange(count, dtype=np.float64)
    rise = np.clip(t / ramp, 0.0, 1.0)
    fall = np.clip((count - 1 - t) / ramp, 0.0, 1.0)
    s = np.minimum(rise, fall)
    weights: Array = s * s * (3.0 - 2.0 * s)
    return weights


def slerp(q0: ArrayLike, q1: ArrayLike, weight: ArrayLike) -> Array:
    """Spherical interpolation of unit quaternions (..., 4) by weight (...,), on the short arc."""
    q0, q1 = np.asarray(q0, dtype=np.float64), np.asarray(q1, dtype=np.float64)
    dot = np.sum(q0 * q1, axis=-1)
    q1 = np.where(dot[..., None] < 0.0, -q1, q1)
    dot = np.clip(np.abs(dot), -1.0, 1.0)
    angle = np.arccos(dot)
    sin = np.sin(angle)
    w = np.asarray(weight, dtype=np.float64)
    near = sin < 1e-6
    a = np.where(near, 1.0 - w, np.sin((1.0 - w) * angle) / np.where(near, 1.0, sin))
    b = np.where(near, w, np.sin(w * angle) / np.where(near, 1.0, sin))
    q = a[..., None] * q0 + b[..., None] * q1
    unit: Array = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return unit


def blend_from_pose(under_quats: ArrayLike, gesture_quats: Array, weights: ArrayLike) -> Array:
    """Blend (N, B, 4) gesture quaternions with the pose underneath ((B, 4) or (N, B, 4)) by (N,) weights."""
    under = np.broadcast_to(under_quats, np.shape(gesture_quats))
    return slerp(under, gesture_quats, np.broadcast_to(np.asarray(weights)[:, None], np.shape(gesture_quats)[:2]))


def pointing_hand_rotations(arm: str, count: int) -> tuple[tuple[str, ...], Array]:
    """Canonical local rotation vectors (count, H, 3) of the pointing hand shape and their bone names."""
    prefix = skeleton.ARM_PREFIX[arm]
    names = tuple(prefix + bone for bone in POINTING_HAND)
    rotvecs = np.broadcast_to(np.array(list(POINTING_HAND.values())), (count, len(names), 3))
    return names, rotvecs


def _standing_pose() -> dict[str, Array]:
    """Canonical local rotation vectors of a natural standing pose: arms hanging 75 degrees down from the
    T-pose, elbows bent 17 degrees forward. Rigs with no animation start and end here, not in their
    bind pose."""
    pose: dict[str, Array] = {}
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        for bone, world in ((side + "Arm", (0.0, sign * 1.3, 0.0)), (side + "ForeArm", (0.0, 0.0, -sign * 0.3))):
            frame = _CANONICAL_FRAMES[bone]
            pose[bone] = matrix_to_rotvec(frame.T @ rotvec_to_matrix(np.array(world)) @ frame)
    return pose


#: Canonical local rotation vectors (3,) of the standing pose, by bone (others stay at rest).
STANDING_POSE = _standing_pose()
#: Degrees: a bone whose rotation underneath is within this of its rest is at rest. An importer's rounding
#: leaves a rest pose off by up to about a degree (a VRM 0.x's arms 0.6-0.9 degrees, after Blender's glTF
#: importer guessed its bind pose; float32 bind matrices a few 1e-5 radians), while a pose an animator sets
#: turns a bone by more. (At 0.06 degrees, such a VRM started and ended every gesture in its T-pose.)
AT_REST_DEGREES = 3.0
#: ... as the sine of half that angle, the length of a unit quaternion's vector part.
AT_REST = math.sin(math.radians(AT_REST_DEGREES) / 2)


class FingerLine(NamedTuple):
    """The rig's pointing line: from `start`'s head through `end`'s head, or through `end`'s tail with
    `to_tail` (a hand without an index finger: the hand's own line)."""
    start: str
    end: str
    to_tail: bool = False

    def points(self, skeleton: RigSkeleton, pose: Array) -> tuple[Array, Array]:
        """(base (..., 3), tip (..., 3)) of the line in (..., B, 4, 4) pose (or rest) matrices of `skeleton`."""
        base = pose[..., skeleton.index[self.start], :3, 3]
        tip = skeleton.tails(pose, self.end) if self.to_tail else pose[..., skeleton.index[self.end], :3, 3]
        return base, tip


def finger_line_bones(roles: Mapping[str, str], arm: str) -> FingerLine:
    """The rig's pointing line (a FingerLine): joint positions, as the mesh shows them, not a finger bone's
    tail (an imported bone's tail may point anywhere). The index finger from its base (Index1) to the
    farthest index joint the rig has (Index4 ... Index2); with Index1 alone, the hand's head to the index
    base; without an index finger, the hand's own line, from its head (the wrist) to its tail (the hand's
    end): a hand without fingers points along itself (aimed along the forearm's line, the hand was 9-17
    degrees off the target: tests/addon/test_fingerless_hands.py)."""
    prefix = skeleton.ARM_PREFIX[arm]
    if f"{prefix}HandIndex1" not in roles:
        return FingerLine(roles[prefix + "Hand"], roles[prefix + "Hand"], to_tail=True)
    index = [roles[f"{prefix}HandIndex{k}"] for k in (1, 2, 3, 4) if f"{prefix}HandIndex{k}" in roles]
    return FingerLine(index[0], index[-1]) if len(index) > 1 else FingerLine(roles[prefix + "Hand"], index[0])


def aim_rig(rig: "RigState", basis: Array, changed: Sequence[int], arm: str, targets: Array,
            weights: ArrayLike) -> Array:
    """(N, 4, 4) basis matrices of the pointing Arm bone turned so the rig's finger line
    (`finger_line_bones`) passes through targets (N, 3) by `weights` (N,) of the turn, solved against
    the posed rig.

    basis: (N, B, 4, 4) every bone's basis as it will play: the gesture's on the bones at indices
    `changed`, over the pose underneath.
    """
    arm_bone = rig.roles[skeleton.ARM_PREFIX[arm] + "Arm"]
    line = finger_line_bones(rig.roles, arm)
    pose = rig.skeleton.pose_after(rig.under_pose_at(len(basis)), rig.under_at(len(basis)), basis, changed,
                                   only=(line.end, arm_bone))
    i = rig.skeleton.index[arm_bone]
    base, tip = line.points(rig.skeleton, pose)
    finger = (tip - base) / np.linalg.norm(tip - base, axis=1, keepdims=True)
    correction = aim.shoulder_corrections(pose[:, i, :3, 3], base, finger, targets)  # (N, 3)
    turn = rotvec_to_matrix(correction * np.asarray(weights)[:, None])
    world = pose[:, i, :3, :3] / np.linalg.norm(pose[:, i, :3, :3], axis=1, keepdims=True)  # (N, 3, 3)
    aimed = basis[:, i].copy()
    aimed[:, :3, :3] = basis[:, i, :3, :3] @ np.swapaxes(world, -1, -2) @ turn @ world
    return aimed


def look_at(rig: "RigState", basis: Array, changed: Sequence[int], eye_bones: Sequence[str], to_character: Array,
            targets: Array, weights: ArrayLike) -> Array:
    """(N, E, 4) local quaternions turning each eye so it looks at targets (N, 3) by `weights` (N,).

    An eye looks along the character's forward at rest, whatever its bone's axes; it is turned from
    where the pose carries that direction (the head's gesture over the pose underneath) onto the target.
    basis: (N, B, 4, 4) the bones' basis as they will play, the gesture's on the bones at `changed`.
    """
    pose = rig.skeleton.pose_after(rig.under_pose_at(len(basis)), rig.under_at(len(basis)), basis, changed,
                                   only=eye_bones)
    forward = to_character.T @ np.array([0.0, -1.0, 0.0])  # armature space
    rows = [rig.skeleton.index[bone] for bone in eye_bones]
    count, eyes = len(basis), len(rows)
    world = rotation_part(pose[:, rows])  # (N, E, 3, 3)
    resting = np.stack([rig.skeleton.rest_frame(bone).T @ forward for bone in eye_bones])  # (E, 3)
    looking = (world @ resting[:, :, None])[..., 0].reshape(-1, 3)  # (N E, 3)
    wanted = (targets[:, None] - pose[:, rows][..., :3, 3]).reshape(-1, 3)
    turn = aim.rotation_between(looking / np.linalg.norm(looking, axis=1, keepdims=True),
                                wanted / np.linalg.norm(wanted, axis=1, keepdims=True)).reshape(count, eyes, 3, 3)
    turn = rotvec_to_matrix(matrix_to_rotvec(turn) * np.asarray(weights)[:, None, None])
    return matrix_to_quat(rotation_part(basis[:, rows]) @ np.swapaxes(world, -1, -2) @ turn @ world)


def hips_relative_targets(rig: "RigState", targets: ArrayLike, count: int) -> Array:
    """(N, 3) targets (3,) or (N, 3) in the rig's armature space, carried back by the motion of its hips
    underneath at each of `count` frames: where each target is for a body whose hips rest.

    The gesture keys the bones above the hips; hips that sway or turn in the rig's own animation carry
    the gesture with them, so the agent is asked for the direction its body sees.
    """
    points = np.broadcast_to(np.asarray(targets, dtype=np.float64), (count, 3))
    if "Hips" not in rig.roles or not rig.animated:
        return points
    i = rig.skeleton.index[rig.roles["Hips"]]
    back = rig.skeleton.rest[i] @ inverse(rig.under_pose_at(count)[:, i])  # (N, 4, 4) pose -> rest
    carried: Array = np.einsum("nij,nj->ni", back[:, :3, :3], points) + back[:, :3, 3]
    return carried


def played_finger_base(canonical: Array, arm: str) -> Array:
    """(N, 3) index-base path of canonical rotations (N, 15, 3) blended from their first frame as the keys
    blend from the pose underneath (`blend_weights`): it comes back to its start even where the agent's
    own hand does not (a target behind the character), so the aim's pointing phase stays whole. Only the
    joints the finger line hangs from are blended."""
    chain = aim.finger_line_joints(arm)
    quats = rotvec_to_quat(canonical[:, chain])  # (N, C, 4)
    played = np.zeros_like(canonical)
    played[:, chain] = quat_to_rotvec(blend_from_pose(quats[0], quats, blend_weights(len(canonical))))
    return aim.finger_lines(played, arm)[1]


#: The roles whose turn a gesture adds to the pose underneath instead of replacing it: the spine, the neck
#: and the head. Gestures on both arms at once both turn them.
TORSO = rig_roles.SPINE + ("Neck", "Head")


def _other_arm_prefix(arm: str) -> str:
    """The role prefix of the arm other than `arm` ("Right" for "LEFT")."""
    return skeleton.ARM_PREFIX[skeleton.ARMS[1 - skeleton.ARMS.index(arm)]]


def free_arm_columns(names: Sequence[str], arm: str) -> list[int]:
    """The columns of `names` (canonical roles) that are the joints of the arm other than `arm`, collar to index
    base."""
    side = _other_arm_prefix(arm)
    return [k for k, name in enumerate(names) if name in skeleton.ACTION_JOINTS and name.startswith(side)]


def owned_joints(arm: str, still: bool) -> tuple[str, ...]:
    """The action joints a gesture on `arm` keys: the spine, neck and head (a turn added to what plays
    underneath), its own arm, and, made as on a still rig, the other arm too (from its natural standing
    pose; on an animated rig the other arm is the animation's)."""
    other = _other_arm_prefix(arm)
    return tuple(joint for joint in skeleton.ACTION_JOINTS if still or not joint.startswith(other))


def _objectives(agent: Agent, request: "GestureRequest", rig: "RigState") -> Array:
    """(M, O) objectives of the request at the agent's rate (M: the gesture's seconds at the agent's rate)."""
    span = request.agent_frames
    rhythm = (agent.wave_rhythm(request.exaggeration, span, request.seed, request.tempo, request.arm)
              if agent.space.behaviour(request.behaviour).oscillates else None)
    if request.targets is not None:
        check_finite_targets(np.broadcast_to(request.targets, (request.frame_count, 3)))
    asked = None if request.targets is None else resample(
        hips_relative_targets(rig, request.targets, request.frame_count), span)  # (M, 3)
    return build_objectives(agent.space, request.behaviour, request.arm, span, targets=asked,
                            rest_heads=rig.rest_heads, exaggeration=request.exaggeration, rhythm=rhythm)


def _conversions(names: Sequence[str], rig: "RigState", to_character: Array) -> tuple[Array, Array]:
    """((D, 3, 3) C, (D, 3, 3) P) of the named roles for `retarget`."""
    swings = rest_swings(rig.roles, rig.rest_heads, rig.rest_tails, to_character)
    frames = [rig.skeleton.rest_frame(rig.roles[n]) for n in names]
    parent_swings = [np.eye(3) if p is None else swings[p] for p in (_parent_role(n, rig.roles) for n in names)]
    return (retarget_matrices(names, frames, to_character, np.array([swings[n] for n in names])),
            retarget_matrices(names, frames, to_character, np.array(parent_swings)))


def _played(request: "GestureRequest", rig: "RigState", canonical: Array,
            pointing: bool) -> tuple[list[str], Array, Array, Array]:
    """(names of the roles keyed, (N, D, 4) the gesture's rotations of them on the rig, (D, 4) the standing
    pose, to_character): the owned action joints, then, for a `pointing` behaviour, the pointing hand shape."""
    names, canonical = fold_missing(canonical, list(skeleton.ACTION_JOINTS), rig.roles)
    owned = owned_joints(request.arm, rig.still)
    kept = [k for k, name in enumerate(names) if name in owned]
    names, canonical = [names[k] for k in kept], canonical[:, kept]
    joints = len(names)
    if pointing:  # one hand shape, held on every frame
        hand_names, hand = pointing_hand_rotations(request.arm, 1)
        present = [i for i, name in enumerate(hand_names) if name in rig.roles]
        names += [hand_names[i] for i in present]
        hand = hand[:, present]  # (1, H, 3)
    to_character = character_frame(rig.rest_heads)
    conversions, parent_conversions = _conversions(names, rig, to_character)
    standing = retarget(np.array([STANDING_POSE.get(n, np.zeros(3)) for n in names]), conversions,
                        parent_conversions)  # (D, 4)
    played = retarget(canonical, conversions[:joints], parent_conversions[:joints])  # (N, J, 4)
    if len(names) > joints:  # the hand shape retargeted once
        held = retarget(hand, conversions[joints:], parent_conversions[joints:])  # (1, H, 4)
        played = np.concatenate([played, np.broadcast_to(held, (len(played),) + held.shape[1:])], axis=1)
    return names, played, standing, to_character


def _blended(rig: "RigState", names: Sequence[str], columns: Sequence[int], played: Array, standing: Array,
             held: Sequence[int] = ()) -> tuple[Array, Array]:
    """((N, D, 4) keyed, (N, D, 4) underneath): each bone blended from the pose it starts from into the
    gesture and back (on a still rig, bones at rest start from the standing pose, not the bind pose); the
    columns `held` (a free arm with no part in the gesture) stay on that start pose on every frame. The
    spine, neck and head take the turn that carries the animation's pose of them (`RigState.animation_at`)
    into the gesture's, by the same weights, on top of the pose underneath: over the animation alone the
    gesture's pose, and over other gestures that turn them too, the turns of all."""
    count = len(played)
    quats: Callable[[Array], Array] = lambda frames: matrix_to_quat(frames[:, columns, :3, :3])  # noqa: E731
    under = each_frame(quats, rig.under_at(count))  # (N, D, 4)
    start = each_frame(quats, rig.start_at(count))
    torso = [k for k, name in enumerate(names) if name in TORSO]
    animation = each_frame(lambda frames: quats(frames)[:, torso], rig.animation_at(count))  # (N, T, 4)
    at_rest = np.zeros(animation.shape[:-1], dtype=bool)
    if rig.still:
        start = np.where((np.linalg.norm(start[..., 1:], axis=-1) < AT_REST)[..., None], standing, start)
        at_rest = np.linalg.norm(animation[..., 1:], axis=-1) < AT_REST
        animation = np.where(at_rest[..., None], standing[torso], animation)
    played = played.copy()
    played[:, list(held)] = start[:, list(held)]  # an arm that has no part in the gesture stays where it was
    weights = blend_weights(count)
    keyed = blend_from_pose(start, played, weights)
    blended = blend_from_pose(animation, played[:, torso], weights)
    conjugate = np.array([1.0, -1.0, -1.0, -1.0])
    turn = np.where(at_rest[..., None], blended, quat_multiply(animation * conjugate, blended))  # (N, T, 4)
    keyed[:, torso] = quat_multiply(under[:, torso], turn)
    for k, bone in ((k, rig.roles[names[column]]) for k, column in enumerate(torso)):
        if bone in rig.above:  # layers above multiply in after this one: under = below above
            above = rig.above[bone]
            keyed[:, torso[k]] = quat_multiply(quat_multiply(quat_multiply(under[:, torso[k]], above * conjugate),
                                                             turn[:, k]), above)
            under[:, torso[k]] = quat_multiply(keyed[:, torso[k]], turn[:, k] * conjugate)
    return keyed, under


def gesture_rotations(agent: Agent, request: "GestureRequest", rig: "RigState") -> tuple[tuple[str, ...], Array, Array]:
    """Per-frame local quaternions to key on the rig: (bone names, keyed (N, D, 4), underneath (N, D, 4)).

    request: a GestureRequest. rig: a RigState (the rig's bones, roles and the pose underneath).
    `keyed` is each bone's rotation as the gesture plays it over the pose underneath; `underneath` the
    rotation it would have without the gesture (its animation, else its pose), which a Combine layer
    needs. The bones are those the gesture owns (`owned_joints`, Point's hand shape, a target behaviour's
    eyes). On a still rig, a behaviour whose free arm has no part in it (the agent's `still_free_arm`) holds
    that arm where it was; on an animated rig the gesture does not key that arm at all. Every RLAnimateError
    is raised before anything is returned, so callers can write all or nothing.
    """
    return aimed(request, rig, blended_gesture(agent, request, rig))


@dataclass(frozen=True)
class Blended:
    """A gesture before its aim (`blended_gesture`): the roles keyed and their columns in the rig's skeleton, the
    (N, D, 4) rotations keyed and underneath, the agent's (N, 3) finger base the aim's phase follows (None but for
    a target behaviour), the rig's character frame, and whether the behaviour aims (Exact Aim applies: a pointing
    behaviour). `aimed` finishes it for a target, and for another."""
    names: tuple[str, ...]
    columns: tuple[int, ...]
    keyed: Array
    under: Array
    phase_base: Array | None
    to_character: Array
    aims: bool


def blended_gesture(agent: Agent, request: "GestureRequest", rig: "RigState") -> Blended:
    """The agent's gesture for the request, retargeted to the rig and blended from and into the pose underneath."""
    rig_roles.check_roles(rig.name, rig.roles, request.arm, rig.family)
    check_length(request.frame_count)
    canonical = run_agent(agent, request.behaviour, _objectives(agent, request, rig), seed=request.seed,
                          frame_count=request.frame_count)  # (N, 15, 3)
    declared = agent.space.behaviour(request.behaviour)
    phase_base = played_finger_base(canonical, request.arm) if declared.kind == behaviours.TARGET else None
    names, played, standing, to_character = _played(request, rig, canonical, declared.aims)
    columns = [rig.skeleton.index[rig.roles[n]] for n in names]  # the eyes, keyed for Point, come after these
    held = free_arm_columns(names, request.arm) if request.behaviour in agent.still_free_arm else []
    keyed, under = _blended(rig, names, columns, played, standing, held)
    return Blended(tuple(names), tuple(columns), keyed, under, phase_base, to_character, declared.aims)


def aimed(request: "GestureRequest", rig: "RigState",
          blended: Blended) -> tuple[tuple[str, ...], Array, Array]:
    """`gesture_rotations`' result from a blended gesture: a target behaviour's aim and gaze solved for the
    request's targets (which may be others than the gesture was made for: Follow Target's cheap path), the
    rotations made continuous; RLAnimateError for rotations that are not numbers."""
    names, columns = list(blended.names), list(blended.columns)
    bones = [rig.roles[n] for n in names]
    keyed, under = np.array(blended.keyed), np.array(blended.under)
    if blended.phase_base is not None:
        bones, keyed, under = _aimed(rig, request, names, columns, keyed, under, blended)
    keyed, under = continuous(keyed), continuous(under)
    finite = np.isfinite(keyed).all(axis=(0, 2)) & np.isfinite(under).all(axis=(0, 2))  # (D,)
    broken = [bone for bone, ok in zip(bones, finite, strict=True) if not ok]
    if broken:
        raise RLAnimateError(f"The gesture's rotations of {', '.join(broken)} are not numbers (NaN): check those "
                             "bones' pose and animation at the gesture's frames and the rig's rest pose for NaN "
                             "values.")
    return tuple(bones), keyed, under


def _aimed(rig: "RigState", request: "GestureRequest", names: list[str], columns: list[int], keyed: Array,
           under: Array, blended: Blended) -> tuple[list[str], Array, Array]:
    """(bones, keyed, under) of a target behaviour: the eyes look at the target, and a pointing behaviour's
    finger is aimed exactly on the rig (Exact Aim), solved against the pose as it will play."""
    phase_base, to_character = blended.phase_base, blended.to_character
    assert phase_base is not None and request.targets is not None  # a target behaviour's, asked with targets
    count = request.frame_count
    bones = [rig.roles[n] for n in names]
    phase = aim.pointing_phase(phase_base)
    targets = np.broadcast_to(request.targets, (count, 3))
    under_basis = rig.under_at(count)
    basis = under_basis.copy()
    basis[:, columns, :3, :3] = quat_to_matrix(keyed) * each_frame(
        lambda frames: np.linalg.norm(frames[:, columns, :3, :3], axis=-2, keepdims=True), under_basis)
    if request.exact_aim and blended.aims:
        arm_column = names.index(skeleton.ARM_PREFIX[request.arm] + "Arm")
        aimed = aim_rig(rig, basis, columns, request.arm, targets, phase)
        keyed[:, arm_column] = matrix_to_quat(rotation_part(aimed))
        basis[:, columns[arm_column]] = aimed
    eyes = [role for role in ("LeftEye", "RightEye") if role in rig.roles]
    if not eyes:
        return bones, keyed, under
    eye_bones = [rig.roles[e] for e in eyes]
    looking = look_at(rig, basis, columns, eye_bones, to_character, targets, phase)  # (N, E, 4)
    eye_columns = [rig.skeleton.index[b] for b in eye_bones]
    under = np.concatenate([under, each_frame(
        lambda frames: matrix_to_quat(frames[:, eye_columns, :3, :3]), under_basis)], axis=1)
    return bones + eye_bones, np.concatenate([keyed, looking], axis=1), under


class GestureRequest:
    """What the user asked for: behaviour, arm, length in scene frames at the scene's `fps`, seed, the
    behaviour's attribute, a wave's tempo (Hz; None: the agent's choice), and whether Point solves its aim
    exactly on the rig (else it keys the agent's own aim)."""

    def __init__(self, behaviour: str, arm: str, frame_count: int, *, targets: ArrayLike | None = None,
                 exaggeration: float = 0.5, seed: int | None = None, tempo: float | None = None,
                 exact_aim: bool = True, fps: float = frame_rate.AGENT_FPS) -> None:
        self.behaviour, self.arm = behaviour, arm
        self.frame_count, self.seed = int(frame_count), seed
        self.targets, self.exaggeration, self.tempo = targets, float(exaggeration), tempo
        self.exact_aim = bool(exact_aim)
        self.fps = float(fps)

    @property
    def agent_frames(self) -> int:
        """The gesture's length at the agent's rate (core/frame_rate.py)."""
        return frame_rate.agent_frames(self.frame_count, self.fps)


class RigState:
    """The rig as the pipeline needs it.

    skeleton: a core.rig.RigSkeleton of the bones that play roles, each parented to the bone of its
    nearest canonical ancestor's role; roles: {role: bone name} (core.rig_roles); family: the naming
    it was matched by (for messages); under, under_pose: (B, 4, 4) or (N, B, 4, 4) each bone's basis
    and armature-space pose matrices as the rig plays without the gesture, at each gesture frame (the
    pose by forward kinematics when None); animated: whether they are animation (Point's targets are then
    carried back by the hips' motion underneath).

    still: the gesture is made as on a rig without animation (default: when not animated): bones at rest
    start and end in the standing pose, and the other arm is keyed too. held: frames at the start over which
    the gesture starts from the pose of its first frame (a handover: the pose the earlier gesture has there).
    resting: {bone: (4, 4) basis} bones that start from this basis whatever plays underneath (a gesture
    made on a still rig, baked again under gestures that move those bones: it starts where it first did).
    bare: {bone: (N, 4, 4) basis} the spine, neck and head as the animation plays them without the turns
    other gestures add to them (where those differ from `under`). above: {bone: (N, 4) quaternion} the turn
    the layers above the gesture's own add to them (their Combine layers multiply in, in the stack's order).
    """

    def __init__(self, name: str, skeleton_: RigSkeleton, roles: Mapping[str, str], family: str, under: ArrayLike,
                 animated: bool, under_pose: ArrayLike | None = None, *, still: bool | None = None, held: int = 0,
                 resting: Mapping[str, Array] | None = None, bare: Mapping[str, Array] | None = None,
                 above: Mapping[str, Array] | None = None) -> None:
        self.name, self.skeleton, self.roles, self.family = name, skeleton_, dict(roles), family
        self.under, self.animated = np.asarray(under, dtype=np.float64), animated
        if under_pose is None:
            every = [skeleton_.names[i] for i in range(len(skeleton_.names))]
            under_pose = skeleton_.pose_matrices(self.under, only=every)
        self.under_pose = np.asarray(under_pose, dtype=np.float64)
        self.still = (not animated) if still is None else bool(still)
        self.held, self.resting = int(held), dict(resting or {})
        self.bare, self.above = dict(bare or {}), dict(above or {})

    def with_pose(self, under: ArrayLike, under_pose: ArrayLike | None) -> "RigState":
        """This rig with another pose underneath (basis, pose), its other settings kept."""
        return RigState(self.name, self.skeleton, self.roles, self.family, under, self.animated, under_pose,
                        still=self.still, held=self.held, resting=self.resting, bare=self.bare, above=self.above)

    def under_at(self, count: int) -> Array:
        """(N, B, 4, 4) basis matrices underneath at each of `count` frames."""
        return np.broadcast_to(self.under, (count,) + self.under.shape[-3:])

    def animation_at(self, count: int) -> Array:
        """(N, B, 4, 4) basis matrices of the animation underneath: `under`, but the spine, neck and head
        without other gestures' turns (`bare`) and the `resting` bones at their basis."""
        pose = self.under_at(count)
        if not self.resting and not self.bare:
            return pose
        pose = np.array(pose)
        for bone, basis in (self.bare | self.resting).items():
            pose[:, self.skeleton.index[bone]] = basis
        return pose

    def start_at(self, count: int) -> Array:
        """(N, B, 4, 4) basis matrices the gesture blends from and back to: `animation_at`, but over the `held`
        frames the pose underneath at the first frame (where the gesture it takes over from is)."""
        start = self.animation_at(count)
        if not self.held:
            return start
        start = np.array(start)
        start[:self.held] = self.under_at(count)[0]
        return start

    def under_pose_at(self, count: int) -> Array:
        """(N, B, 4, 4) pose matrices underneath at each of `count` frames."""
        return np.broadcast_to(self.under_pose, (count,) + self.under_pose.shape[-3:])

    @property
    def rest_heads(self) -> dict[str, Array]:
        """{role: (3,) rest head in armature space}."""
        return {role: self.skeleton.rest_head(bone) for role, bone in self.roles.items()}

    @property
    def rest_tails(self) -> dict[str, Array]:
        """{role: (3,) rest tail in armature space}."""
        return {role: self.skeleton.tails(self.skeleton.rest, bone) for role, bone in self.roles.items()}


def role_skeleton(roles: Mapping[str, str], rest: Mapping[str, Array], lengths: Mapping[str, float]) -> RigSkeleton:
    """A RigSkeleton of the bones playing `roles` ({role: bone}), each parented to the bone of its
    nearest canonical ancestor that the rig has; rest: {bone: (4, 4)}, lengths: {bone: float}."""
    ordered = [name for name in skeleton.BONE_NAMES if name in roles]  # canonical order: parents first
    parents: list[str | None] = []
    for role in ordered:
        parent = skeleton.BONE_BY_NAME[role].parent
        while parent is not None and parent not in roles:
            parent = skeleton.BONE_BY_NAME[parent].parent
        parents.append(None if parent is None else roles[parent])
    bones = [roles[r] for r in ordered]
    return RigSkeleton(bones, parents, [rest[b] for b in bones], [lengths[b] for b in bones])


def canonical_rig() -> RigState:
    """The canonical skeleton at rest, unanimated, as a RigState: for tests and checks without Blender."""
    bones = skeleton.BONES
    rigged = RigSkeleton([b.name for b in bones], [b.parent for b in bones], skeleton.rest_matrices(),
                         [np.linalg.norm(np.subtract(b.tail, b.head)) for b in bones])
    return RigState("Canonical", rigged, {b.name: b.name for b in bones}, "Mixamo",
                    np.tile(np.eye(4), (len(bones), 1, 1)), animated=False)
