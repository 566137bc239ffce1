"""Bone-name maps from source skeletons to the canonical rig (core.skeleton), as plain constants.

A BoneMap names, for one source skeleton:
    to_canonical  source bone name (without any `prefix:`) -> canonical bone name;
    shared_bend   canonical bones the source lacks -> the canonical bone whose source rotation they
                  share (the source's one spine bone bends both canonical Spine and Spine1);
    calibration   the source pose that corresponds to the canonical rest directions-wise:
                  "rest" when the source's rest pose is a T-pose like the canonical one (Mixamo),
                  "first_frame" when the rest pose is meaningless and every clip starts standing
                  neutrally (the Bandai Namco capture: its zero-rotation pose is a straight line).
"""
from collections import namedtuple
from collections.abc import Iterable, Sequence

from . import skeleton

BoneMap = namedtuple("BoneMap", "name to_canonical shared_bend calibration")

#: Mixamo: the canonical names themselves, with or without `mixamorig:`, `mixamorig1:`, ... prefixes.
MIXAMO = BoneMap("Mixamo", {name: name for name in skeleton.BONE_NAMES}, {}, "rest")

#: Bandai Namco Research motion dataset (../shared/realmocap/README.md): 22 joints, no fingers, no Spine1.
BANDAI_NAMCO = BoneMap(
    "Bandai Namco",
    {
        "Hips": "Hips", "Spine": "Spine", "Chest": "Spine2", "Neck": "Neck", "Head": "Head",
        "Shoulder_L": "LeftShoulder", "UpperArm_L": "LeftArm", "LowerArm_L": "LeftForeArm", "Hand_L": "LeftHand",
        "Shoulder_R": "RightShoulder", "UpperArm_R": "RightArm", "LowerArm_R": "RightForeArm", "Hand_R": "RightHand",
        "UpperLeg_L": "LeftUpLeg", "LowerLeg_L": "LeftLeg", "Foot_L": "LeftFoot", "Toes_L": "LeftToeBase",
        "UpperLeg_R": "RightUpLeg", "LowerLeg_R": "RightLeg", "Foot_R": "RightFoot", "Toes_R": "RightToeBase",
    },
    {"Spine1": "Spine"},
    "first_frame",
)

BONE_MAPS = (MIXAMO, BANDAI_NAMCO)

#: Canonical bones a clip must drive: the action joints. Index fingers may be missing (they stay at rest).
CLIP_BONES = tuple(j for j in skeleton.ACTION_JOINTS if "HandIndex" not in j)


def source_key(bone_name: str) -> str:
    """A source bone's name without its namespace prefix: 'mixamorig1:LeftArm' -> 'LeftArm'."""
    return bone_name.rsplit(":", 1)[-1]


def match_bones(source_names: Iterable[str], bone_map: BoneMap) -> dict[str, str]:
    """{canonical name: source bone name} for the source bones that `bone_map` knows."""
    matched = {}
    for name in source_names:
        canonical = bone_map.to_canonical.get(source_key(name))
        if canonical is not None and canonical not in matched:
            matched[canonical] = name
    return matched


def missing_bones(source_names: Iterable[str], bone_map: BoneMap, required: Sequence[str] = CLIP_BONES) -> list[str]:
    """Source-side names of the bones `bone_map` needs for `required` that `source_names` lacks."""
    present = match_bones(source_names, bone_map)
    wanted = [c for c in required if c not in bone_map.shared_bend]
    from_canonical = {c: s for s, c in bone_map.to_canonical.items()}
    return [from_canonical[c] for c in wanted if c not in present]


def best_bone_map(source_names: Iterable[str], maps: Sequence[BoneMap] = BONE_MAPS) -> BoneMap:
    """The map that recognises the most of `source_names` (ties go to the earlier map)."""
    return max(maps, key=lambda m: (len(match_bones(source_names, m)), -maps.index(m)))
