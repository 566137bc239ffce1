"""The canonical character: Mixamo bone names, rest geometry, and the bones each space uses.

Coordinates are the armature's own space in metres, Blender's convention for a Mixamo character
imported from FBX: +Z up, the character faces -Y, and its left hand is at +X. The rest pose is
Mixamo's T-pose. Each bone is (name, parent, head, tail, z_hint): as in Blender, a bone's local Y
axis runs from head to tail, and its local Z axis is `z_hint` made orthogonal to Y (what
`EditBone.align_roll(z_hint)` does). Local rotations (pose-bone rotations) are relative to this
rest frame, so the same numbers mean the same motion on any rig that shares the rest frames.
"""
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

PREFIX = "mixamorig:"

Vector3 = tuple[float, float, float]


class Bone(NamedTuple):
    name: str
    parent: str | None
    head: Vector3
    tail: Vector3
    z_hint: Vector3


_UP: Vector3 = (0.0, 0.0, 1.0)
_FORWARD: Vector3 = (0.0, -1.0, 0.0)

_CENTRE_BONES = [
    Bone("Hips", None, (0.0, 0.01, 1.00), (0.0, 0.01, 1.09), _FORWARD),
    Bone("Spine", "Hips", (0.0, 0.01, 1.09), (0.0, 0.005, 1.21), _FORWARD),
    Bone("Spine1", "Spine", (0.0, 0.005, 1.21), (0.0, 0.0, 1.34), _FORWARD),
    Bone("Spine2", "Spine1", (0.0, 0.0, 1.34), (0.0, 0.0, 1.47), _FORWARD),
    Bone("Neck", "Spine2", (0.0, 0.0, 1.47), (0.0, -0.01, 1.57), _FORWARD),
    Bone("Head", "Neck", (0.0, -0.01, 1.57), (0.0, -0.01, 1.78), _FORWARD),
    Bone("HeadTop_End", "Head", (0.0, -0.01, 1.78), (0.0, -0.01, 1.81), _FORWARD),
]

# Left side only; the right side mirrors it in X (see _mirror).
_FINGER_BASES: dict[str, tuple[Vector3, Vector3, tuple[float, float, float, float]]] = {
    # name: (base position, direction, phalanx lengths 1-4)
    "Thumb": ((0.725, -0.030, 1.425), (0.55, -0.75, -0.35), (0.040, 0.034, 0.030, 0.024)),
    "Index": ((0.795, -0.026, 1.450), (1.0, -0.03, 0.0), (0.045, 0.028, 0.022, 0.020)),
    "Middle": ((0.800, -0.006, 1.450), (1.0, 0.0, 0.0), (0.048, 0.031, 0.024, 0.020)),
    "Ring": ((0.796, 0.013, 1.449), (1.0, 0.03, 0.0), (0.044, 0.028, 0.022, 0.019)),
    "Pinky": ((0.786, 0.031, 1.447), (1.0, 0.07, -0.02), (0.035, 0.022, 0.018, 0.016)),
}


def _left_side_bones() -> list[Bone]:
    bones = [
        Bone("LeftEye", "Head", (0.032, -0.085, 1.665), (0.032, -0.110, 1.665), _UP),
        # The collar starts 2 cm in front of the shoulder joint, as a clavicle runs back from the
        # sternum. This also keeps its rest frame 10 degrees off gimbal lock relative to Spine2 (Euler
        # XYZ (-84.9, -79.7, 0)); in the spine's plane it sat at Y = 90, where the XYZ Euler keys of an
        # FBX file lose up to a few millimetres on frames whose collar turn is tiny.
        Bone("LeftShoulder", "Spine2", (0.060, -0.020, 1.440), (0.170, 0.0, 1.450), _UP),
        Bone("LeftArm", "LeftShoulder", (0.170, 0.0, 1.450), (0.450, 0.0, 1.450), _UP),
        Bone("LeftForeArm", "LeftArm", (0.450, 0.0, 1.450), (0.700, 0.0, 1.450), _UP),
        Bone("LeftHand", "LeftForeArm", (0.700, 0.0, 1.450), (0.800, -0.006, 1.450), _UP),
    ]
    for finger, (base, direction, lengths) in _FINGER_BASES.items():
        unit = np.asarray(direction) / np.linalg.norm(direction)
        head = np.asarray(base)
        parent = "LeftHand"
        for k, length in enumerate(lengths, start=1):
            tail = head + unit * length
            name = f"LeftHand{finger}{k}"
            bones.append(Bone(name, parent, tuple(head), tuple(tail), _UP))
            head, parent = tail, name
    bones += [
        Bone("LeftUpLeg", "Hips", (0.090, 0.0, 0.970), (0.090, 0.0, 0.540), _FORWARD),
        Bone("LeftLeg", "LeftUpLeg", (0.090, 0.0, 0.540), (0.090, 0.020, 0.090), _FORWARD),
        Bone("LeftFoot", "LeftLeg", (0.090, 0.020, 0.090), (0.090, -0.100, 0.025), _UP),
        Bone("LeftToeBase", "LeftFoot", (0.090, -0.100, 0.025), (0.090, -0.170, 0.020), _UP),
        Bone("LeftToe_End", "LeftToeBase", (0.090, -0.170, 0.020), (0.090, -0.200, 0.020), _UP),
    ]
    return bones


def _mirror(bone: Bone) -> Bone:
    def flip(p: Vector3) -> Vector3:
        return (-p[0], p[1], p[2])

    def rename(name: str) -> str:
        return name.replace("Left", "Right") if name.startswith("Left") else name

    parent = None if bone.parent is None else rename(bone.parent)
    return Bone(rename(bone.name), parent, flip(bone.head), flip(bone.tail), bone.z_hint)


_LEFT = _left_side_bones()
#: Every bone of the canonical rig, parents before children.
BONES = tuple(_CENTRE_BONES + _LEFT + [_mirror(b) for b in _LEFT])
BONE_BY_NAME = {b.name: b for b in BONES}
BONE_NAMES = tuple(b.name for b in BONES)

#: The 15 joints the agent rotates (the action space), in action order.
ACTION_JOINTS = (
    "Spine", "Spine1", "Spine2", "Neck", "Head",
    "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand", "LeftHandIndex1",
    "RightShoulder", "RightArm", "RightForeArm", "RightHand", "RightHandIndex1",
)

#: The 10 description joints (positions), in description order; each is the head of the named bone.
DESCRIPTION_JOINTS = (
    ("left_collar", "LeftShoulder"), ("right_collar", "RightShoulder"),
    ("left_shoulder", "LeftArm"), ("right_shoulder", "RightArm"),
    ("left_elbow", "LeftForeArm"), ("right_elbow", "RightForeArm"),
    ("left_wrist", "LeftHand"), ("right_wrist", "RightHand"),
    ("left_index_base", "LeftHandIndex1"), ("right_index_base", "RightHandIndex1"),
)

#: The 4 effectors (unit vectors), in description order: (name, from-bone head, to-bone head or None).
#: An eye's vector is its bone's Y axis (head to tail); a finger's runs from its base to its tip.
EFFECTORS = (
    ("left_eye", "LeftEye", None), ("right_eye", "RightEye", None),
    ("left_index", "LeftHandIndex1", "LeftHandIndex4"), ("right_index", "RightHandIndex1", "RightHandIndex4"),
)

#: Bones a rig must have for the agent to drive it and to be described.
REQUIRED_BONES = tuple(sorted(set(ACTION_JOINTS) | {b for _, b in DESCRIPTION_JOINTS}
                              | {"LeftEye", "RightEye", "LeftHandIndex4", "RightHandIndex4", "Hips"}))

ARMS = ("LEFT", "RIGHT")
ARM_PREFIX = {"LEFT": "Left", "RIGHT": "Right"}


def rest_frame(bone: Bone) -> npt.NDArray[np.float64]:
    """(3, 3) rest rotation of a bone in armature space; columns are its local X, Y, Z axes."""
    y = np.subtract(bone.tail, bone.head)
    y = y / np.linalg.norm(y)
    z = np.asarray(bone.z_hint, dtype=np.float64)
    z = z - y * np.dot(z, y)
    z = z / np.linalg.norm(z)
    x = np.cross(y, z)
    return np.stack([x, y, z], axis=1)


def rest_matrices() -> npt.NDArray[np.float64]:
    """(B, 4, 4) armature-space rest matrices of BONES, in BONES order."""
    mats = np.tile(np.eye(4), (len(BONES), 1, 1))
    for i, bone in enumerate(BONES):
        mats[i, :3, :3] = rest_frame(bone)
        mats[i, :3, 3] = bone.head
    return mats


def shoulder_rest_position(arm: str) -> npt.NDArray[np.float64]:
    """Rest position (3,) of the pointing arm's shoulder joint: where pointing vectors start."""
    return np.asarray(BONE_BY_NAME[ARM_PREFIX[arm] + "Arm"].head)


def strip_prefix(name: str) -> str:
    """'mixamorig:LeftArm', 'mixamorig1:LeftArm' or 'LeftArm' -> 'LeftArm'."""
    return name.split(":", 1)[1] if ":" in name else name
