"""From a gesture request to per-frame local bone rotations on a user's rig, in plain numpy.

The pipeline Generate Gesture runs, with Blender only at its two ends (reading the rig and the
target, writing keys):

    targets (N, 3) in the rig's armature space --pointing_directions--> objectives (N, 7)
    --agent.rollout--> actions (M, 45) --decode, time_scale--> canonical rotations (N, 15, 3)
    --aim.aim_at (POINT, exact aim)--> --retarget--> rig quaternions (N, 15, 4) --blend_from_pose--> keys

A rig may differ from the canonical skeleton in three ways, all handled here:
  * scale and units (a Mixamo FBX in centimetres): only directions and rotations are used;
  * the orientation of its armature space (an FBX whose armature space is Y-up): `character_frame`
    finds the rotation from the rig's armature space to the character frame (+X left, -Y forward,
    +Z up) from its own rest joints;
  * its bones' rest frames (rolls, directions): `retarget_matrices` gives C per bone with
    C = F_can^-1 A F_rig (F: armature-space rest rotations, A: armature -> character frame), and
    the rig's local rotation is R_rig = C^-1 R_can C, which gives every bone the same armature-space
    rotation from rest as on the canonical skeleton.
"""
import numpy as np

from . import aim, skeleton, spaces
from .errors import RLAnimateError
from .rotations import matrix_to_quat, rotvec_to_matrix

#: Lengths the agent supports, as fractions of its learned average length (paper Section 4.4).
SUPPORTED_LENGTH = (0.4, 1.5)
#: Fraction of the gesture spent blending in from, and back out to, the rig's pose at the start frame.
BLEND_FRACTION = 0.2
#: Bones of the pointing hand shape, with their canonical local rotation vectors (radians): the
#: thumb tucked and the three other fingers curled towards the palm (negative about the local X
#: axis curls a finger of either hand towards the palm of the T-pose).
_CURL = {"1": 1.2, "2": 1.4, "3": 1.0}
POINTING_HAND = {
    **{f"{finger}{k}": (-angle, 0.0, 0.0)
       for finger in ("HandMiddle", "HandRing", "HandPinky") for k, angle in _CURL.items()},
    "HandThumb1": (-0.35, 0.0, 0.25), "HandThumb2": (-0.5, 0.0, 0.0), "HandThumb3": (-0.4, 0.0, 0.0),
}


def supported_length_range(average_frames):
    """(shortest, longest) gesture length in frames the agent portrays without visible artefacts."""
    low, high = SUPPORTED_LENGTH
    return max(2, int(round(low * average_frames))), max(2, int(round(high * average_frames)))


#: Rest joints that fix a rig's orientation: the torso and the shoulders (present on every Mixamo rig).
_ORIENTATION_BONES = ("Hips", "Spine", "Spine1", "Spine2", "Neck", "Head",
                      "LeftShoulder", "RightShoulder", "LeftArm", "RightArm")


def character_frame(rest_heads):
    """(3, 3) rotation A taking vectors in a rig's armature space to the character frame.

    rest_heads: mapping of canonical bone name -> rest head (3,) in the rig's armature space. A is
    the rotation that best lays the rig's torso and shoulder joints onto the canonical ones (Kabsch),
    so it ignores the rig's units and proportions; the character frame has +X left, -Y forward, +Z up.
    """
    rig = np.array([rest_heads[name] for name in _ORIENTATION_BONES], dtype=np.float64)  # (J, 3)
    canonical = np.array([skeleton.BONE_BY_NAME[name].head for name in _ORIENTATION_BONES])
    rig, canonical = rig - rig.mean(axis=0), canonical - canonical.mean(axis=0)
    u, _, vt = np.linalg.svd(canonical.T @ rig)
    sign = np.sign(np.linalg.det(u @ vt))
    return u @ np.diag([1.0, 1.0, sign]) @ vt


def pointing_directions(arm, targets, rest_heads):
    """(N, 3) unit vectors in the character frame from the rig's rest shoulder to each target.

    targets: (N, 3) target positions in the rig's armature space (any units, the rig's own).
    """
    shoulder = np.asarray(rest_heads[skeleton.ARM_PREFIX[arm] + "Arm"], dtype=np.float64)
    offsets = np.atleast_2d(np.asarray(targets, dtype=np.float64)) - shoulder  # (N, 3)
    norms = np.linalg.norm(offsets, axis=1)
    scale = np.linalg.norm(np.subtract(rest_heads["Head"], rest_heads["Hips"]))
    if not np.all(np.isfinite(norms)) or np.any(norms < 1e-3 * scale):
        raise RLAnimateError("The target sits on the pointing shoulder: move it away from the character.")
    return (offsets / norms[:, None]) @ character_frame(rest_heads).T


def canonical_targets(arm, targets, rest_heads):
    """(N, 3) targets placed on the canonical skeleton as they sit relative to the rig.

    The direction from the rig's rest shoulder is kept (`pointing_directions`), and the distance is
    scaled by the canonical over the rig's Hips-to-Head length, so units and proportions drop out.
    """
    shoulder = np.asarray(rest_heads[skeleton.ARM_PREFIX[arm] + "Arm"], dtype=np.float64)
    distances = np.linalg.norm(np.atleast_2d(np.asarray(targets, dtype=np.float64)) - shoulder, axis=1)
    head, hips = skeleton.BONE_BY_NAME["Head"].head, skeleton.BONE_BY_NAME["Hips"].head
    scale = np.linalg.norm(np.subtract(head, hips)) / np.linalg.norm(np.subtract(rest_heads["Head"], rest_heads["Hips"]))
    directions = pointing_directions(arm, targets, rest_heads)  # (N, 3)
    return skeleton.shoulder_rest_position(arm) + directions * (distances * scale)[:, None]


def build_objectives(behaviour, arm, frame_count, *, targets=None, rest_heads=None, exaggeration=0.5):
    """(N, 7) objectives for a gesture: POINT needs targets (N, 3) and rest_heads; WAVE an exaggeration."""
    if int(frame_count) < 2:
        raise RLAnimateError(f"The gesture is {int(frame_count)} frames long: set a length of at least 2 frames.")
    if behaviour == "POINT":
        if targets is None:
            raise RLAnimateError("Point needs a target: pick a target object, or tick 'Use 3D Cursor'.")
        attributes = pointing_directions(arm, targets, rest_heads)
    else:
        attributes = exaggeration
    return spaces.make_objective(behaviour, arm, attributes, frame_count)


def resample(values, count):
    """Linear resampling of (M, ...) values along the first axis to (count, ...), ends kept."""
    values = np.asarray(values, dtype=np.float64)
    if len(values) == count:
        return values.copy()
    position = np.linspace(0.0, len(values) - 1, count)
    low = np.floor(position).astype(int)
    high = np.minimum(low + 1, len(values) - 1)
    frac = (position - low).reshape((-1,) + (1,) * (values.ndim - 1))
    return values[low] * (1.0 - frac) + values[high] * frac


def rollout_length(frame_count, average_frames):
    """Steps the agent runs for a gesture of frame_count frames: clamped into its supported range."""
    shortest, longest = supported_length_range(average_frames)
    return int(np.clip(frame_count, shortest, longest))


def run_agent(agent, behaviour, objectives, seed=None):
    """Canonical local rotation vectors (N, 15, 3) for the objectives (N, 7).

    Lengths outside the supported range are time-scaled: the agent runs at the nearest supported
    length and its actions are resampled to N frames.
    """
    count = len(objectives)
    steps = rollout_length(count, agent.average_frames[behaviour])
    agent_objectives = resample(objectives, steps)
    agent_objectives[:, spaces.OBJECTIVE_TIME] = np.linspace(0.0, 1.0, steps)
    if behaviour == "POINT":
        attrs = agent_objectives[:, spaces.OBJECTIVE_ATTRIBUTES]
        agent_objectives[:, spaces.OBJECTIVE_ATTRIBUTES] = attrs / np.linalg.norm(attrs, axis=1, keepdims=True)
    actions = np.asarray(agent.rollout(agent_objectives, seed=seed), dtype=np.float64)  # (steps, 45)
    if actions.shape != (steps, spaces.ACTION_SIZE) or not np.all(np.isfinite(actions)):
        raise RLAnimateError(f"The agent returned actions of shape {actions.shape} or non-finite values: "
                             "choose another agent file in the add-on preferences.")
    return spaces.decode_action(resample(actions, count), np.asarray(agent.action_bounds))


_CANONICAL_FRAMES = {bone.name: skeleton.rest_frame(bone) for bone in skeleton.BONES}


def retarget_matrices(canonical_bones, rig_rest_frames, to_character):
    """(B, 3, 3) C = F_can^-1 A F_rig for each named canonical bone.

    rig_rest_frames: (B, 3, 3) armature-space rest rotations of the rig's bones (columns: local axes).
    """
    canonical = np.stack([_CANONICAL_FRAMES[name] for name in canonical_bones])
    return np.swapaxes(canonical, -1, -2) @ to_character @ np.asarray(rig_rest_frames, dtype=np.float64)


def retarget(canonical_rotvecs, conversions):
    """Canonical local rotation vectors (..., B, 3) -> the rig's local quaternions (..., B, 4).

    R_rig = C^-1 R_can C per bone, with C from `retarget_matrices`.
    """
    rotations = rotvec_to_matrix(canonical_rotvecs)  # (..., B, 3, 3)
    return matrix_to_quat(np.swapaxes(conversions, -1, -2) @ rotations @ conversions)


def blend_weights(count, fraction=BLEND_FRACTION):
    """(count,) weights of the gesture against the start pose: 0 at both ends, 1 in the middle.

    Smoothstep ramps over `fraction` of the frames at each end keep velocity continuous.
    """
    ramp = max(1, int(round(fraction * (count - 1))))
    t = np.arange(count, dtype=np.float64)
    rise = np.clip(t / ramp, 0.0, 1.0)
    fall = np.clip((count - 1 - t) / ramp, 0.0, 1.0)
    s = np.minimum(rise, fall)
    return s * s * (3.0 - 2.0 * s)


def slerp(q0, q1, weight):
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
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def blend_from_pose(start_quats, gesture_quats, weights):
    """Blend (N, B, 4) gesture quaternions with the (B, 4) start pose by (N,) weights."""
    start = np.broadcast_to(start_quats, np.shape(gesture_quats))
    return slerp(start, gesture_quats, np.broadcast_to(np.asarray(weights)[:, None], np.shape(gesture_quats)[:2]))


def continuous(quats):
    """(N, B, 4) quaternions with signs flipped so each is on the same hemisphere as the previous frame.

    Keys are interpolated channel by channel; without this a sign flip between two frames would
    swing the bone the long way round.
    """
    q = np.asarray(quats, dtype=np.float64)
    steps = np.where(np.sum(q[1:] * q[:-1], axis=-1) < 0.0, -1.0, 1.0)  # (N-1, B)
    signs = np.concatenate([np.ones((1,) + q.shape[1:-1]), np.cumprod(steps, axis=0)])  # (N, B)
    return q * signs[..., None]


def pointing_hand_rotations(arm, count):
    """Canonical local rotation vectors (count, H, 3) of the pointing hand shape and their bone names."""
    prefix = skeleton.ARM_PREFIX[arm]
    names = tuple(prefix + bone for bone in POINTING_HAND)
    rotvecs = np.broadcast_to(np.array(list(POINTING_HAND.values())), (count, len(names), 3))
    return names, rotvecs


def gesture_rotations(agent, request, rig):
    """Per-frame local quaternions to key on the rig: (bone names, (N, B, 4)).

    request: a GestureRequest. rig: a RigPose (the rig's rest data and its pose at the start frame).
    Every RLAnimateError is raised before anything is returned, so callers can write all or nothing.
    """
    missing = sorted(set(skeleton.REQUIRED_BONES) - set(rig.rest_heads))
    if missing:
        raise RLAnimateError(f"The rig lacks the bones {', '.join(missing)}: use a rig with Mixamo bone names.")
    objectives = build_objectives(request.behaviour, request.arm, request.frame_count, targets=request.targets,
                                  rest_heads=rig.rest_heads, exaggeration=request.exaggeration)
    canonical = run_agent(agent, request.behaviour, objectives, seed=request.seed)  # (N, 15, 3)
    names = list(skeleton.ACTION_JOINTS)
    if request.behaviour == "POINT" and request.exact_aim:
        targets = canonical_targets(request.arm, request.targets, rig.rest_heads)
        canonical = aim.aim_at(canonical, request.arm, np.broadcast_to(targets, (len(canonical), 3)))
    if request.behaviour == "POINT":
        hand_names, hand = pointing_hand_rotations(request.arm, request.frame_count)
        present = [i for i, name in enumerate(hand_names) if name in rig.rest_frames]
        names += [hand_names[i] for i in present]
        canonical = np.concatenate([canonical, hand[:, present]], axis=1)
    to_character = character_frame(rig.rest_heads)
    conversions = retarget_matrices(names, [rig.rest_frames[n] for n in names], to_character)
    quats = retarget(canonical, conversions)  # (N, B, 4)
    start = np.array([rig.start_quats[n] for n in names])  # (B, 4)
    keyed = blend_from_pose(start, quats, blend_weights(request.frame_count))
    return tuple(names), continuous(keyed)


class GestureRequest:
    """What the user asked for: behaviour, arm, length, seed and the behaviour's attribute.

    exact_aim: for POINT, turn the agent's arm so the index finger passes through the target
    (core/aim.py, the final polish); False keys the agent's own aim."""

    def __init__(self, behaviour, arm, frame_count, *, targets=None, exaggeration=0.5, seed=None, exact_aim=True):
        self.behaviour, self.arm = behaviour, arm
        self.frame_count, self.seed = int(frame_count), seed
        self.targets, self.exaggeration = targets, float(exaggeration)
        self.exact_aim = bool(exact_aim)


class RigPose:
    """The rig as the pipeline needs it, keyed by canonical bone name (prefix stripped).

    rest_heads: name -> (3,) rest head in armature space; rest_frames: name -> (3, 3) rest rotation
    in armature space; start_quats: name -> (4,) local rotation at the start frame.
    """

    def __init__(self, rest_heads, rest_frames, start_quats):
        self.rest_heads, self.rest_frames, self.start_quats = rest_heads, rest_frames, start_quats


def canonical_rig_pose():
    """The canonical skeleton at rest as a RigPose: for tests and for checking an agent without Blender."""
    heads = {b.name: np.asarray(b.head, dtype=np.float64) for b in skeleton.BONES}
    frames = {b.name: skeleton.rest_frame(b) for b in skeleton.BONES}
    identity = {b.name: np.array([1.0, 0.0, 0.0, 0.0]) for b in skeleton.BONES}
    return RigPose(heads, frames, identity)

