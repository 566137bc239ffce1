"""Procedural pointing and waving clips on the canonical rig, in plain numpy.

A gesture spec (behaviour, arm, target or exaggeration, style seed) becomes per-frame local rotation
vectors, at 30 fps, for the 15 action joints and the finger bones. The motion is built the way an
animator blocks it: key poses (neutral, the pointing hold or the raised wave), solved in world space
with analytic two-bone IK, then timed per body part with minimum-jerk segments:

    time ->  lead-in | anticipation | stroke        | settle | hold ...... | return       | settle | rest
    gaze     .........=======>                                   ====>
    torso    ..............=============>                          =========>
    arm      ...........<-- ======================> ~~~>             ==============> ~~>
    hand     ......................===================>                ==============>

Gaze (neck, head; the eyes ride on the head) leads, the torso follows, the arm winds up slightly,
strokes with a bell-shaped speed profile, overshoots a little and settles; the hand and fingers
arrive last. Every clip starts and ends in the same relaxed neutral pose (`neutral_pose`).

Pointing contract: at the hold the index-finger base lies on the ray from the arm's rest shoulder
joint along `spaces.pointing_direction(arm, target)`, and the finger (Index1 head -> Index4 head)
runs along that ray, so its line passes through the target at any distance.
"""
from dataclasses import dataclass

import numpy as np

from rlanimate_addon.core import skeleton, spaces
from rlanimate_addon.core.easing import minimum_jerk
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.rotations import matrix_to_rotvec, rotvec_to_matrix

FPS = 30
MAX_WAVING = 1.7  # s of oscillation at most, so no clip runs past 4.5 s

_FINGERS = ("Thumb", "Index", "Middle", "Ring", "Pinky")
#: Finger bones each clip animates besides the action joints (Index2/3 stay at rest: the agent
#: cannot move them, so the clips keep them straight).
FINGER_BONES = tuple(f"{side}Hand{finger}{k}" for side in ("Left", "Right") for finger in _FINGERS
                     for k in (1, 2, 3) if not (finger == "Index" and k > 1))
ANIMATED_BONES = tuple(skeleton.ACTION_JOINTS) + tuple(b for b in FINGER_BONES if b not in skeleton.ACTION_JOINTS)

_UP = np.array([0.0, 0.0, 1.0])
_FORWARD = np.array([0.0, -1.0, 0.0])
_SIDE_SIGN = {"LEFT": 1.0, "RIGHT": -1.0}  # +X is the character's left
_OTHER_ARM = {"LEFT": "RIGHT", "RIGHT": "LEFT"}

# ---------------------------------------------------------------------------------------------
# Rest geometry and a small batched pose evaluator (same convention as core.kinematics).

_PARENT = {b.name: b.parent for b in skeleton.BONES}
_REST = {b.name: skeleton.rest_frame(b) for b in skeleton.BONES}
_HEAD = {b.name: np.asarray(b.head, dtype=np.float64) for b in skeleton.BONES}
_REST_LOCAL = {n: _REST[n] if p is None else _REST[p].T @ _REST[n] for n, p in _PARENT.items()}
_OFFSET = {n: None if p is None else _REST[p].T @ (_HEAD[n] - _HEAD[p]) for n, p in _PARENT.items()}


def _length(child, parent):
    return float(np.linalg.norm(_HEAD[child] - _HEAD[parent]))


class _Pose:
    """Local rotation matrices (..., 3, 3) of some bones; the rest stay at rest."""

    def __init__(self, local=None):
        self.local = dict(local or {})

    def world(self, name):
        """(..., 3, 3) armature-space rotation of a bone; its columns are the bone's axes."""
        parent = _PARENT[name]
        base = _REST_LOCAL[name] if parent is None else self.world(parent) @ _REST_LOCAL[name]
        return base @ self.local[name] if name in self.local else base

    def head(self, name):
        """(..., 3) armature-space position of a bone's head."""
        parent = _PARENT[name]
        if parent is None:
            return _HEAD[name]
        return self.head(parent) + (self.world(parent) @ _OFFSET[name][:, None])[..., 0]

    def set_world(self, name, rotation):
        """Give a bone the armature-space rotation (..., 3, 3), keeping its parent where it is."""
        parent = _PARENT[name]
        base = _REST_LOCAL[name] if parent is None else self.world(parent) @ _REST_LOCAL[name]
        self.local[name] = np.swapaxes(base, -1, -2) @ rotation

    def turn(self, name, rotvec):
        """Rotate a bone (and so its children) by an armature-space rotation vector (..., 3)."""
        self.set_world(name, rotvec_to_matrix(rotvec) @ self.world(name))

    def rotvecs(self, names):
        return {n: matrix_to_rotvec(self.local[n]) if n in self.local else np.zeros(3) for n in names}


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _perpendicular(v, axis):
    """Unit component of v (..., 3) perpendicular to the unit axis (..., 3)."""
    return _unit(v - np.sum(v * axis, axis=-1, keepdims=True) * axis)


def _frame_from(primary_local, secondary_local, primary_world, secondary_world):
    """(..., 3, 3) rotation taking primary_local to primary_world, and secondary_local as close as
    it can to secondary_world."""
    def basis(a, b):
        a = _unit(a)
        b = _perpendicular(b, a)
        return np.stack([a, b, np.cross(a, b)], axis=-1)

    return basis(primary_world, secondary_world) @ np.swapaxes(basis(primary_local, secondary_local), -1, -2)


def _axis_rotation(axis, angle):
    """(..., 3, 3) rotation by angle (...) about a unit axis (..., 3)."""
    return rotvec_to_matrix(np.asarray(axis) * np.asarray(angle)[..., None])


def _twist_angle(rotation):
    """Angle (...) of the twist about local Y in the swing-twist split of a local rotation."""
    rv = matrix_to_rotvec(rotation)
    angle = np.linalg.norm(rv, axis=-1)
    half = 0.5 * angle
    sin_ratio = np.where(angle > 1e-9, np.sin(half) / np.maximum(angle, 1e-9), 0.5)
    return 2.0 * np.arctan2(rv[..., 1] * sin_ratio, np.cos(half))


# ---------------------------------------------------------------------------------------------
# Specs and style.

@dataclass(frozen=True)
class GestureSpec:
    """What to perform. `target` (3,) in the character frame for POINT; `exaggeration` in [0, 1]
    for WAVE. `seed` picks the style (timing and posture variation)."""
    behaviour: str
    arm: str
    target: tuple = None
    exaggeration: float = None
    seed: int = 0


@dataclass(frozen=True)
class Style:
    """Moderate per-clip variation: the agent sees only t/N and the label, so timing stays close."""
    tempo: float          # scales every duration
    lead_in: float        # s in the neutral pose before anything moves
    hold: float           # s of pointing hold
    anticipation: float   # wind-up, as a fraction of the stroke
    overshoot: float      # past the key pose before settling, as a fraction of the stroke
    swivel: float         # rad added to the natural elbow swivel
    extension: float      # shoulder-to-wrist distance / arm length at the hold
    palm_roll: float      # rad the pointing palm turns from facing down towards the body
    head_tilt: float      # rad of friendly head tilt
    wave_frequency: float  # Hz
    wave_cycles: int


def draw_style(seed):
    """The style of clip `seed`, deterministic."""
    rng = np.random.default_rng(np.random.SeedSequence([0x5EED, int(seed)]))
    return Style(
        tempo=float(np.clip(rng.normal(1.0, 0.04), 0.92, 1.08)),
        lead_in=float(rng.uniform(0.25, 0.4)),
        hold=float(rng.uniform(0.75, 1.0)),
        anticipation=float(rng.uniform(0.04, 0.07)),
        overshoot=float(rng.uniform(0.025, 0.045)),
        swivel=float(rng.uniform(-0.12, 0.12)),
        extension=float(rng.uniform(0.975, 0.99)),
        palm_roll=float(rng.uniform(0.35, 0.65)),
        head_tilt=float(rng.uniform(0.04, 0.1)),
        wave_frequency=float(rng.uniform(2.2, 2.7)),
        wave_cycles=int(rng.integers(3, 5)),
    )


# ---------------------------------------------------------------------------------------------
# Timing.

def keyed_progress(times, knots):
    """Progress at `times` (T,) through (time, value) knots, minimum-jerk between consecutive knots:
    every knot is reached at rest, so the curve is smooth (C2) and each segment's speed one bell."""
    out = np.full(np.shape(times), float(knots[0][1]))
    for (t0, v0), (t1, v1) in zip(knots[:-1], knots[1:]):
        inside = times >= t0
        out = np.where(inside, v0 + (v1 - v0) * minimum_jerk((times - t0) / max(t1 - t0, 1e-9)), out)
    return out


def _blend(name, start, end, progress):
    """Local rotations (T, 3, 3) of bone `name` from start (3, 3) to end ((T,) 3, 3) at progress (T,),
    which may leave [0, 1] for anticipation and overshoot. The bone's direction moves along a great
    circle while its roll turns evenly (swing-twist), so no bone wobbles off its path."""
    rest = _REST_LOCAL[name]
    first, last = rest @ start, rest @ end  # orientations in the parent's frame
    y0, y1 = first[..., :, 1], last[..., :, 1]
    axis = np.cross(y0, y1)
    sine = np.linalg.norm(axis, axis=-1)
    angle = np.arctan2(sine, np.sum(y0 * y1, axis=-1))
    axis = axis / np.maximum(sine, 1e-12)[..., None]
    swung = rotvec_to_matrix(axis * angle[..., None]) @ first  # direction of `last`, roll of `first`
    twist = np.sum(matrix_to_rotvec(last @ np.swapaxes(swung, -1, -2)) * y1, axis=-1)
    progress = np.asarray(progress)
    swing = rotvec_to_matrix(axis * (progress * angle)[..., None])
    direction = (swing @ y0[..., None])[..., 0]
    return rest.T @ (rotvec_to_matrix(direction * (progress * twist)[..., None]) @ swing @ first)


# ---------------------------------------------------------------------------------------------
# Arms: analytic two-bone IK with swivel, forearm twist and hand alignment.

def _side(arm):
    return skeleton.ARM_PREFIX[arm]


def _elbow_position(shoulder, wrist, swivel_direction, upper, lower):
    """Elbow (..., 3) of the two-bone chain shoulder -> wrist, bent towards swivel_direction."""
    reach = wrist - shoulder
    distance = np.linalg.norm(reach, axis=-1, keepdims=True)
    axis = reach / distance
    along = (upper**2 - lower**2 + distance**2) / (2.0 * distance)
    radius = np.sqrt(np.maximum(upper**2 - along**2, 0.0))
    return shoulder + along * axis + radius * _perpendicular(swivel_direction, axis)


def _place_arm(pose, arm, elbow, wrist, hand_rotation):
    """Pose the arm so that its elbow and wrist heads land on `elbow`, `wrist` (..., 3) and the hand
    has the armature-space rotation `hand_rotation`. The elbow is a hinge; the forearm takes the
    twist (pronation) so the wrist only bends."""
    side, sign = _side(arm), _SIDE_SIGN[arm]
    shoulder = pose.head(side + "Arm")
    upper_y = _unit(elbow - shoulder)
    fore_y = _unit(wrist - elbow)
    upper_x = sign * _perpendicular(fore_y, upper_y)  # the forearm folds towards local +X (left)
    upper_z = np.cross(upper_x, upper_y)
    pose.set_world(side + "Arm", np.stack([upper_x, upper_y, upper_z], axis=-1))
    forearm = np.stack([np.cross(fore_y, upper_z), fore_y, upper_z], axis=-1)
    for _ in range(3):  # hand rest is a few degrees off the forearm: converge the twist
        pose.set_world(side + "ForeArm", forearm)
        pose.set_world(side + "Hand", hand_rotation)
        twist = _twist_angle(pose.local[side + "Hand"])
        forearm = forearm @ _axis_rotation(np.array([0.0, 1.0, 0.0]), twist)
    pose.set_world(side + "ForeArm", forearm)
    pose.set_world(side + "Hand", hand_rotation)


def _curl(pose, side, finger, angles, spread=0.0):
    """Flex a finger's three joints by `angles` (rad, towards the palm) and turn its base by `spread`."""
    for k, angle in enumerate(angles, start=1):
        name = f"{side}Hand{finger}{k}"
        pose.local[name] = rotvec_to_matrix(np.array([-angle, 0.0, spread if k == 1 else 0.0]))


_RELAXED_HAND = {"Thumb": (0.15, 0.15, 0.15), "Index": (0.12,), "Middle": (0.2, 0.25, 0.15),
                 "Ring": (0.25, 0.3, 0.2), "Pinky": (0.3, 0.35, 0.22)}
_OPEN_HAND = {"Thumb": (0.05, 0.05, 0.05), "Index": (0.04,), "Middle": (0.08, 0.1, 0.06),
              "Ring": (0.12, 0.12, 0.08), "Pinky": (0.16, 0.15, 0.1)}
_POINTING_HAND = {"Thumb": (0.35, 0.55, 0.6), "Index": (0.0,), "Middle": (1.35, 1.55, 0.95),
                  "Ring": (1.45, 1.6, 1.0), "Pinky": (1.5, 1.55, 0.95)}
_SPREAD = {"Thumb": 0.0, "Index": 0.0, "Middle": 0.0, "Ring": -0.04, "Pinky": -0.1}


def _shape_hand(pose, arm, shape, spread=False):
    """Give the arm's fingers a hand shape (curl angles per finger), fanned out when `spread`."""
    side, sign = _side(arm), _SIDE_SIGN[arm]
    for finger, angles in shape.items():
        _curl(pose, side, finger, angles, sign * _SPREAD[finger] if spread else 0.0)


def _pose_neutral_arm(pose, arm, elbow_bend=0.28):
    """Arm hanging relaxed under gravity from wherever the shoulder is: slightly away from the hip,
    elbow bent `elbow_bend` rad (~16 deg), palm towards the thigh."""
    side, sign = _side(arm), _SIDE_SIGN[arm]
    shoulder = pose.head(side + "Arm")
    upper_dir = _unit([sign * 0.16, -0.03, -1.0])
    fore_dir = _unit(upper_dir * np.cos(elbow_bend) + _perpendicular(_FORWARD, upper_dir) * np.sin(elbow_bend))
    elbow = shoulder + _length(side + "ForeArm", side + "Arm") * upper_dir
    wrist = elbow + _length(side + "Hand", side + "ForeArm") * fore_dir
    hand_y = _unit(fore_dir * np.cos(0.12) + _perpendicular(_FORWARD, fore_dir) * np.sin(0.12))
    # Palm faces the thigh and a little back; the hand's local Z is minus the palm normal.
    hand = _frame_from([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], hand_y, [sign * 1.0, -0.25, 0.0])
    _place_arm(pose, arm, elbow, wrist, hand)
    _shape_hand(pose, arm, _RELAXED_HAND, spread=True)


def _neutral():
    pose = _Pose()
    for arm in skeleton.ARMS:
        _pose_neutral_arm(pose, arm)
    return pose


def neutral_pose():
    """{bone: (3,) local rotation vector} of the shared start and end pose, for ANIMATED_BONES."""
    return _neutral().rotvecs(ANIMATED_BONES)


_CHEST = "Spine2"


def _arc(start, end, progress):
    """Rotations (T, 3, 3) that carry the unit vector `start` along its great circle towards `end`
    ((T,) 3), by the fraction `progress` (T,) of the way."""
    frames = np.shape(progress)
    d0 = np.broadcast_to(start, frames + (3,))
    d1 = np.broadcast_to(end, frames + (3,))
    axis = np.cross(d0, d1)
    sine = np.linalg.norm(axis, axis=-1)
    angle = np.arctan2(sine, np.sum(d0 * d1, axis=-1))
    axis = axis / np.maximum(sine, 1e-12)[..., None]
    return rotvec_to_matrix(axis * (np.asarray(progress) * angle)[..., None])


def _apply(rotation, vector):
    return (rotation @ vector[..., None])[..., 0]


def _arm_keys(pose, arm):
    """Where `pose` puts the arm, in the chest's frame: the directions of the wrist and of the elbow
    from the shoulder, the wrist's distance, and the hand's rotation."""
    side = _side(arm)
    to_chest = np.swapaxes(pose.world(_CHEST), -1, -2)
    shoulder = pose.head(side + "Arm")
    reach = (to_chest @ (pose.head(side + "Hand") - shoulder)[..., None])[..., 0]
    elbow = (to_chest @ (pose.head(side + "ForeArm") - shoulder)[..., None])[..., 0]
    distance = np.linalg.norm(reach, axis=-1)
    return {"wrist": reach / distance[..., None], "distance": distance, "elbow": _unit(elbow),
            "hand": to_chest @ pose.world(side + "Hand")}


def _move_arm(pose, arm, start, end, progress, hand_progress, fold=0.0):
    """Pose the arm on every frame between two `_arm_keys`. The wrist travels on a great-circle arc
    about the shoulder with its distance eased (shortened by `fold` mid-way, so the elbow bends to
    swing the arm and extends again), the elbow's direction swings on its own arc (the swivel), and
    the hand turns by `hand_progress`. Progress (T,) may leave [0, 1] for anticipation and overshoot."""
    side = _side(arm)
    frames = progress.shape
    upper, lower = _length(side + "ForeArm", side + "Arm"), _length(side + "Hand", side + "ForeArm")
    distance = start["distance"] + progress * (end["distance"] - start["distance"])
    distance = np.minimum(distance * (1.0 - fold * np.sin(np.pi * np.clip(progress, 0, 1)) ** 2),
                          0.999 * (upper + lower))
    hand_start = np.broadcast_to(start["hand"], frames + (3, 3))
    hand_turn = matrix_to_rotvec(np.swapaxes(hand_start, -1, -2) @ end["hand"])
    hand = hand_start @ rotvec_to_matrix(np.asarray(hand_progress)[..., None] * hand_turn)

    # The elbow's offset from the shoulder-wrist line rides along with the wrist's arc (parallel
    # transport), turning evenly about that line to its end swivel: no fixed reference, no flips.
    carry = _arc(start["wrist"], end["wrist"], progress)
    direction = _apply(carry, np.broadcast_to(start["wrist"], frames + (3,)))
    offset = np.broadcast_to(_perpendicular(start["elbow"], start["wrist"]), frames + (3,))
    carried = _apply(_arc(start["wrist"], end["wrist"], np.ones(frames)), offset)
    target = _perpendicular(end["elbow"], end["wrist"])
    swivel = np.arctan2(np.sum(np.cross(carried, target) * end["wrist"], axis=-1), np.sum(carried * target, axis=-1))
    hint = _apply(rotvec_to_matrix(direction * (progress * swivel)[..., None]), _apply(carry, offset))

    chest = pose.world(_CHEST)
    shoulder = pose.head(side + "Arm")
    wrist = shoulder + _apply(chest, distance[..., None] * direction)
    elbow = _elbow_position(shoulder, wrist, _apply(chest, hint), upper, lower)
    _place_arm(pose, arm, elbow, wrist, chest @ hand)


# ---------------------------------------------------------------------------------------------
# Pointing.

def _aim_head(pose, look_at, tilt=0.0, neck_share=0.4):
    """Turn neck and head (yaw, then pitch; the eyes ride on the head) so the eyes look at `look_at`."""
    for _ in range(2):  # the eyes sit in front of the neck pivot: one correction removes parallax
        eyes = 0.5 * (pose.head("LeftEye") + pose.head("RightEye"))
        current = _unit(pose.world("LeftEye")[..., :, 1])
        wanted = _unit(np.asarray(look_at) - eyes)
        yaw = np.arctan2(wanted[..., 0], -wanted[..., 1]) - np.arctan2(current[..., 0], -current[..., 1])
        yaw = (yaw + np.pi) % (2 * np.pi) - np.pi
        turned = (_axis_rotation(_UP, yaw) @ current[..., None])[..., 0]
        pitch = np.arcsin(np.clip(wanted[..., 2], -1, 1)) - np.arcsin(np.clip(turned[..., 2], -1, 1))
        lateral = _perpendicular(np.cross(turned, _UP), _UP)
        rotation = _axis_rotation(lateral, pitch) @ _axis_rotation(_UP, yaw)
        rotvec = matrix_to_rotvec(rotation)
        pose.turn("Neck", neck_share * rotvec)
        pose.turn("Head", (1.0 - neck_share) * rotvec)
        neck_share = 0.0
    if np.any(tilt):
        pose.turn("Head", np.asarray(tilt)[..., None] * _unit(pose.world("LeftEye")[..., :, 1]))


def _turn_torso(pose, rotvec, shares=(0.3, 0.35, 0.35)):
    for bone, share in zip(("Spine", "Spine1", "Spine2"), shares):
        pose.turn(bone, share * np.asarray(rotvec))


def _pointing_geometry(arm, target):
    """Azimuth (0 ahead, + out to the arm's side, - across the body), elevation and distance."""
    sign = _SIDE_SIGN[arm]
    direction = spaces.pointing_direction(arm, target)
    azimuth = np.arctan2(sign * direction[0], -direction[1])
    elevation = np.arcsin(np.clip(direction[2], -1.0, 1.0))
    distance = np.linalg.norm(np.asarray(target) - skeleton.shoulder_rest_position(arm))
    return direction, azimuth, elevation, distance


def _pointing_hold(arm, target, style):
    """The hold pose of a pointing gesture; the other arm stays neutral."""
    pose = _neutral()
    side, sign = _side(arm), _SIDE_SIGN[arm]
    direction, azimuth, elevation, distance = _pointing_geometry(arm, target)

    # Torso: turn a fraction of the way towards the target (more when it is across the body) and
    # lean a little towards it, more for low and far targets.
    yaw = 0.2 * azimuth + 0.22 * min(azimuth, 0.0)
    horizontal = _unit([direction[0], direction[1], 0.0]) if np.hypot(*direction[:2]) > 1e-3 else _FORWARD
    lean = 0.03 + 0.025 * (distance - 1.5) + 0.22 * max(-elevation, 0.0) - 0.05 * max(elevation, 0.0)
    lean_axis = np.cross(_UP, horizontal)
    _turn_torso(pose, sign * yaw * _UP)
    _turn_torso(pose, lean * lean_axis)

    # Gaze leads to the target; the eyes follow the head.
    _aim_head(pose, np.asarray(target, dtype=np.float64), tilt=0.3 * style.head_tilt * -sign)
    # The free arm keeps hanging under gravity however the torso turns and leans, elbow a bit softer.
    _pose_neutral_arm(pose, _OTHER_ARM[arm], elbow_bend=0.36)

    # Clavicle: rises once the arm is above the shoulder, comes forward for targets ahead/across.
    rise = 0.32 * max(elevation + 0.1, 0.0)
    protraction = 0.1 * np.cos(elevation) * max(np.cos(azimuth), 0.0) + 0.12 * max(-azimuth, 0.0)
    pose.turn(side + "Shoulder", rise * sign * -np.array([0.0, 1.0, 0.0]) + protraction * -sign * _UP)

    # Hand: the index finger along the pointing ray, palm down and rolled towards the body.
    hand_rest = _REST[side + "Hand"]
    finger_local = hand_rest.T @ _unit(_HEAD[side + "HandIndex4"] - _HEAD[side + "HandIndex1"])
    base_local = hand_rest.T @ (_HEAD[side + "HandIndex1"] - _HEAD[side + "Hand"])
    down = _perpendicular(-_UP, direction) if abs(direction[2]) < 0.97 else _perpendicular(_FORWARD, direction)
    medial = _perpendicular(np.cross(direction, down) * -sign, direction)
    roll = style.palm_roll + 0.4 * max(elevation, 0.0)
    palm_normal = np.cos(roll) * down + np.sin(roll) * medial
    hand = _frame_from(finger_local, [0.0, 0.0, 1.0], direction, -palm_normal)  # local Z = -palm normal

    # Wrist on the ray: index base = rest shoulder + lambda * direction, at the chosen reach.
    shoulder = pose.head(side + "Arm")
    upper, lower = _length(side + "ForeArm", side + "Arm"), _length(side + "Hand", side + "ForeArm")
    reach = style.extension * (upper + lower)
    offset = skeleton.shoulder_rest_position(arm) - hand @ base_local - shoulder
    along = offset @ direction
    lam = -along + np.sqrt(along**2 - offset @ offset + reach**2)
    wrist = skeleton.shoulder_rest_position(arm) + lam * direction - hand @ base_local

    # Elbow: hangs down and out, more out for high and across-body targets.
    swivel = 0.45 + 0.35 * max(elevation, 0.0) + 0.3 * max(-azimuth, 0.0) + style.swivel
    axis = _unit(wrist - shoulder)
    outward = _perpendicular(sign * np.array([1.0, 0.0, 0.0]) + 0.3 * _UP, axis)
    hang = _perpendicular(-_UP + 0.2 * sign * np.array([1.0, 0.0, 0.0]), axis)
    elbow = _elbow_position(shoulder, wrist, np.cos(swivel) * hang + np.sin(swivel) * outward, upper, lower)
    _place_arm(pose, arm, elbow, wrist, hand)

    _shape_hand(pose, arm, _POINTING_HAND)
    pose.local[side + "HandIndex1"] = np.eye(3)
    return pose


# ---------------------------------------------------------------------------------------------
# Waving.

_ADDRESSEE = np.array([0.0, -2.5, 1.62])  # whom the character waves at: ahead, at eye height


def _wave_pose(arm, exaggeration, style, phase, envelope):
    """Raised-arm wave poses (T,) at oscillation `phase` (T,) rad, scaled by `envelope` (T,) in [0, 1].

    Both arm segments move in one plane that faces forward and out, so the elbow works as a hinge:
    the forearm sways about the elbow; the upper arm joins in (leading a little) as exaggeration
    grows; the wrist lags behind the forearm (overlapping action)."""
    e = float(exaggeration)
    side, sign = _side(arm), _SIDE_SIGN[arm]
    pose = _Pose({name: np.broadcast_to(m, phase.shape + (3, 3)) for name, m in _neutral().local.items()})

    lean = -sign * (0.02 + 0.05 * e + 0.015 * e * envelope * np.sin(phase - 0.6))
    _turn_torso(pose, lean[:, None] * np.array([0.0, 1.0, 0.0]))
    _aim_head(pose, _ADDRESSEE + np.array([0.0, 0.0, 0.25 * e]),
              tilt=np.full(phase.shape, -sign * style.head_tilt * (0.7 + 0.6 * e)))
    _pose_neutral_arm(pose, _OTHER_ARM[arm], elbow_bend=0.32)

    amplitude = (0.22 + 0.38 * e) * envelope                       # forearm sway, rad
    upper_amplitude = (0.08 + 0.42 * e) * amplitude                # whole-arm involvement
    flap = (0.22 - 0.1 * e) * envelope * np.sin(phase - 0.8)       # wrist, lagging
    upper_angle = 0.75 + 1.45 * e + upper_amplitude * np.sin(phase + 0.5)
    fore_angle = 2.85 + 0.2 * e + amplitude * np.sin(phase)

    rise = 0.05 + 0.3 * e + 0.25 * upper_amplitude * np.sin(phase + 0.5)
    pose.turn(side + "Shoulder", rise[:, None] * (-sign * np.array([0.0, 1.0, 0.0])))

    tilt = 0.45 - 0.15 * e  # plane turned forward from the frontal plane
    lateral = np.array([sign * np.cos(tilt), -np.sin(tilt), 0.0])

    def in_plane(angle):
        return np.cos(angle)[:, None] * -_UP + np.sin(angle)[:, None] * lateral

    shoulder = pose.head(side + "Arm")
    upper, lower = _length(side + "ForeArm", side + "Arm"), _length(side + "Hand", side + "ForeArm")
    elbow = shoulder + upper * in_plane(upper_angle)
    wrist = elbow + lower * in_plane(fore_angle)
    palm_forward = _unit(_FORWARD + 0.25 * sign * np.array([1.0, 0.0, 0.0]))
    hand_y = in_plane(fore_angle + flap + 0.06)
    hand = _frame_from([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], hand_y, np.broadcast_to(-palm_forward, hand_y.shape))
    _place_arm(pose, arm, elbow, wrist, hand)
    _shape_hand(pose, arm, _OPEN_HAND, spread=True)
    return pose


# ---------------------------------------------------------------------------------------------
# Clips.

_GROUPS = {  # body part -> bones whose timing it sets (the other arm's bones stay neutral)
    "torso": ("Spine", "Spine1", "Spine2"),
    "gaze": ("Neck", "Head"),
    "arm": ("Shoulder",),  # the arm, forearm and hand follow the wrist's path (_move_arm)
    "hand": tuple(f"Hand{finger}{k}" for finger in _FINGERS for k in (1, 2, 3)
                              if not (finger == "Index" and k > 1)),
}


def _group_bones(group, arm):
    if group == "torso":  # the free arm re-hangs as the torso moves
        return _GROUPS[group] + tuple(_side(_OTHER_ARM[arm]) + b for b in ("Arm", "ForeArm", "Hand"))
    if group == "gaze":
        return _GROUPS[group]
    return tuple(_side(arm) + b for b in _GROUPS[group])


@dataclass
class GestureClip:
    """A synthesised clip: local rotation vectors per animated bone, and its phases (frame ranges,
    end inclusive), e.g. 'stroke' and 'hold' for POINT, 'raise', 'wave', 'lower' for WAVE."""
    spec: GestureSpec
    rotvecs: dict      # bone name -> (F, 3), for ANIMATED_BONES
    phases: dict       # name -> (first frame, last frame)
    fps: int = FPS

    @property
    def frames(self):
        return len(next(iter(self.rotvecs.values())))

    def action_rotvecs(self):
        """(F, 15, 3) rotation vectors of skeleton.ACTION_JOINTS, in action order."""
        return np.stack([self.rotvecs[j] for j in skeleton.ACTION_JOINTS], axis=1)


def _frames_between(times, start, end):
    inside = np.nonzero((times >= start - 1e-9) & (times <= end + 1e-9))[0]
    return int(inside[0]), int(inside[-1])


def _assemble(spec, end, progress, times, phases, fold=0.0):
    """The clip from neutral to the `end` pose (batch () or (T,)) and back: every bone blends by its
    group's progress; the gesturing arm follows its wrist's path."""
    neutral = _neutral()
    pose = _Pose()
    for name in ANIMATED_BONES:
        start = neutral.local.get(name, np.eye(3))
        group = next((g for g in _GROUPS if name in _group_bones(g, spec.arm)), None)
        if group is None:
            pose.local[name] = np.broadcast_to(start, times.shape + (3, 3))
        else:
            goal = np.broadcast_to(end.local.get(name, np.eye(3)), times.shape + (3, 3))
            pose.local[name] = _blend(name, start, goal, progress[group])
    _move_arm(pose, spec.arm, _arm_keys(neutral, spec.arm), _arm_keys(end, spec.arm),
              progress["arm"], progress["hand"], fold)
    rotvecs = {name: matrix_to_rotvec(pose.local[name]) for name in ANIMATED_BONES}
    phases = {k: _frames_between(times, *v) for k, v in phases.items()}
    return GestureClip(spec, rotvecs, phases)


def _synthesise_point(spec, style):
    target = np.asarray(spec.target, dtype=np.float64)
    _, azimuth, elevation, _ = _pointing_geometry(spec.arm, target)
    hold = _pointing_hold(spec.arm, target, style)
    k = style.tempo
    lead, wind, settle = style.lead_in, 0.22 * k, 0.28 * k
    stroke = (0.62 + 0.1 * max(elevation, 0.0) + 0.1 * max(-azimuth, 0.0)) * k
    back, back_settle, rest = 0.85 * k, 0.3 * k, 0.3
    t1 = lead + wind + stroke
    t2 = t1 + settle + style.hold * k
    total = t2 + back + back_settle + rest
    times = np.arange(int(round(total * FPS)) + 1) / FPS
    overshoot = style.overshoot
    knots = {
        "gaze": [(0, 0), (lead, 0), (lead + wind + 0.55 * stroke, 1), (t2 - 0.1, 1), (t2 - 0.1 + 0.75 * back, 0)],
        "torso": [(0, 0), (lead + 0.5 * wind, 0), (t1 + 0.05, 1), (t2, 1), (t2 + back, 0)],
        "arm": [(0, 0), (lead, 0), (lead + wind, -style.anticipation), (t1, 1 + overshoot), (t1 + settle, 1),
                (t2, 1), (t2 + back, -0.5 * overshoot), (t2 + back + back_settle, 0)],
        "hand": [(0, 0), (lead + wind, 0), (t1 + 0.15, 1), (t2 + 0.05, 1),
                 (t2 + 0.05 + back, 0)],
    }
    progress = {g: keyed_progress(times, kn) for g, kn in knots.items()}
    return _assemble(spec, hold, progress, times,
                     {"stroke": (lead + wind, t1), "hold": (t1 + settle, t2), "return": (t2, t2 + back)},
                     fold=0.05)


def _synthesise_wave(spec, style):
    e = float(spec.exaggeration)
    k = style.tempo
    lead, wind, rise = style.lead_in, 0.15 * k, (0.7 + 0.15 * e) * k
    lower, settle, rest = (0.8 + 0.1 * e) * k, 0.3 * k, 0.25
    frequency = style.wave_frequency - 0.2 * e  # bigger waves swing a little slower
    t_start = lead + wind + rise - 0.15
    t_stop = t_start + min(style.wave_cycles / frequency, MAX_WAVING)
    t_lower = t_stop - 0.1
    total = t_lower + lower + settle + rest
    times = np.arange(int(round(total * FPS)) + 1) / FPS
    envelope = keyed_progress(times, [(0, 0), (t_start, 0), (t_start + 0.3, 1), (t_stop - 0.3, 1), (t_stop, 0)])
    phase = 2 * np.pi * frequency * np.clip(times - t_start, 0.0, None)
    raised = _wave_pose(spec.arm, e, style, phase, envelope)
    knots = {
        "gaze": [(0, 0), (lead - 0.05, 0), (lead + wind + 0.6 * rise, 1), (t_lower, 1), (t_lower + 0.7 * lower, 0)],
        "torso": [(0, 0), (lead + 0.1, 0), (lead + wind + rise, 1), (t_lower, 1), (t_lower + lower, 0)],
        "arm": [(0, 0), (lead, 0), (lead + wind, -0.04), (lead + wind + rise, 1), (t_lower, 1),
                (t_lower + lower, -0.02), (t_lower + lower + settle, 0)],
        "hand": [(0, 0), (lead + wind, 0), (lead + wind + 0.85 * rise, 1), (t_lower + 0.1, 1),
                 (t_lower + 0.1 + lower, 0)],
    }
    progress = {g: keyed_progress(times, kn) for g, kn in knots.items()}
    return _assemble(spec, raised, progress, times,
                     {"raise": (lead + wind, t_start), "wave": (t_start, t_stop), "lower": (t_stop, t_lower + lower)},
                     fold=0.08)


def synthesise(spec):
    """GestureClip for a GestureSpec; raises RLAnimateError for an unusable spec."""
    if spec.behaviour not in spaces.BEHAVIOURS:
        raise RLAnimateError(f"Unknown behaviour {spec.behaviour!r}: use POINT or WAVE.")
    if spec.arm not in skeleton.ARMS:
        raise RLAnimateError(f"Unknown arm {spec.arm!r}: use LEFT or RIGHT.")
    style = draw_style(spec.seed)
    if spec.behaviour == "POINT":
        if spec.target is None or np.shape(spec.target) != (3,):
            raise RLAnimateError("A pointing gesture needs a target (x, y, z) in the character frame.")
        return _synthesise_point(spec, style)
    if spec.exaggeration is None or not 0.0 <= float(spec.exaggeration) <= 1.0:
        raise RLAnimateError("A wave needs an exaggeration between 0 and 1.")
    return _synthesise_wave(spec, style)
