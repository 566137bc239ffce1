"""Which bone of a user's armature plays which canonical role (core.skeleton names), and which are needed.

A role is a canonical bone name ('Spine1', 'LeftArm', 'RightHandIndex1'). A rig family names its bones
for the roles with left-side templates in which `{s}` stands for the family's side token; the right
side swaps the token. Names are compared case-insensitively and without spaces, after dropping any
namespace ('mixamorig1:', 'Armature|'), a Mixamo prefix, glued ('mixamorigLeftArm') or joined by
'_', and a 3ds Max Biped prefix ('Bip01 ').

A bone map ({role: bone name}) comes from the family that matches the most roles, or from a bone-map
file the user loads in the panel (JSON: {"family": name, "bones": {role: bone name}}).
"""
import json
import re
from collections import Counter
from collections.abc import Iterable, Mapping
from functools import lru_cache
from typing import NamedTuple

from .errors import RLAnimateError

#: {role (its left form for a side role): the family's candidate bone names, `{s}` for its side token}
Templates = Mapping[str, tuple[str, ...]]


class Family(NamedTuple):
    name: str
    sides: tuple[str, str]  # the side tokens, left and right
    templates: Templates

SPINE = ("Spine", "Spine1", "Spine2")
_CENTRE = ("Hips",) + SPINE + ("Neck", "Head")
_FINGERS = ("Thumb", "Index", "Middle", "Ring", "Pinky")
#: Side roles in their left form (canonical names).
_SIDE = ("LeftEye", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand") + tuple(
    f"LeftHand{finger}{k}" for finger in _FINGERS for k in range(1, 5))
ROLES = _CENTRE + _SIDE + tuple(r.replace("Left", "Right", 1) for r in _SIDE)


def _fingers(pattern: str, names: Mapping[str, str] | None = None,
             counts: Iterable[int] = (1, 2, 3)) -> dict[str, tuple[str, ...]]:
    """Finger templates: pattern.format(finger=..., k=...) per canonical finger and phalanx."""
    names = names or {f: f.lower() for f in _FINGERS}
    return {f"LeftHand{f}{k}": (pattern.format(finger=names[f], k=k),) for f in _FINGERS for k in counts}


def _family(name: str, sides: tuple[str, str], centre: Templates, side: Templates, fingers: Templates) -> Family:
    return Family(name, sides, {**centre, **side, **fingers})


MIXAMO = _family(
    "Mixamo", ("Left", "Right"),
    {r: (r,) for r in _CENTRE},
    {r: ("{s}" + r[len("Left"):],) for r in _SIDE[:5]},
    {f"LeftHand{f}{k}": (f"{{s}}Hand{f}{k}",) for f in _FINGERS for k in range(1, 5)})

_RIGIFY_FINGERS = _fingers("{finger}.0{k}{{s}}", {f: ("thumb" if f == "Thumb" else "f_" + f.lower()) for f in _FINGERS})

#: Rigify's spine FK controls below its torso pivot (spine_fk, spine_fk.001) turn the hips, not the
#: chest: the gesture's spine goes on the two above it (Spine2 folds into Spine1).
RIGIFY = _family(
    "Rigify", (".L", ".R"),
    {"Spine": ("spine_fk.002",), "Spine1": ("spine_fk.003",), "Neck": ("neck",), "Head": ("head",)},
    {"LeftShoulder": ("shoulder{s}",), "LeftArm": ("upper_arm_fk{s}",), "LeftForeArm": ("forearm_fk{s}",),
     "LeftHand": ("hand_fk{s}",)},
    _RIGIFY_FINGERS)

#: Blender's human metarig numbers its spine (spine = the hips, spine.001, ...); metarig-style rigs
#: exported from other tools (UniVRM's Seed-san) name it hips > spine > chest > neck > head.
METARIG = _family(
    "Blender human metarig", (".L", ".R"),
    {"Hips": ("hips", "spine"), "Spine": ("spine.001", "spine"), "Spine1": ("spine.002", "chest"),
     "Spine2": ("spine.003", "upper_chest"), "Neck": ("spine.004", "neck"), "Head": ("spine.006", "head")},
    {"LeftEye": ("eye{s}",), "LeftShoulder": ("shoulder{s}",), "LeftArm": ("upper_arm{s}",),
     "LeftForeArm": ("forearm{s}",), "LeftHand": ("hand{s}",)},
    _RIGIFY_FINGERS)

UNREAL = _family(
    "Unreal Engine mannequin", ("_l", "_r"),
    {"Hips": ("pelvis",), "Spine": ("spine_01",), "Spine1": ("spine_02",), "Spine2": ("spine_05", "spine_03"),
     "Neck": ("neck_01",), "Head": ("head",)},
    {"LeftShoulder": ("clavicle{s}",), "LeftArm": ("upperarm{s}",), "LeftForeArm": ("lowerarm{s}",),
     "LeftHand": ("hand{s}",)},
    _fingers("{finger}_0{k}{{s}}"))

AUTO_RIG_PRO = _family(
    "Auto-Rig Pro", (".l", ".r"),
    {"Hips": ("c_root.x", "root.x"), "Spine": ("c_spine_01.x", "spine_01.x"),
     "Spine1": ("c_spine_02.x", "spine_02.x"), "Spine2": ("c_spine_03.x", "spine_03.x"),
     "Neck": ("c_neck.x", "neck.x"), "Head": ("c_head.x", "head.x")},
    {"LeftEye": ("c_eye{s}",), "LeftShoulder": ("c_shoulder{s}", "shoulder{s}"),
     "LeftArm": ("c_arm_fk{s}", "arm_stretch{s}", "arm{s}"),
     "LeftForeArm": ("c_forearm_fk{s}", "forearm_stretch{s}", "forearm{s}"),
     "LeftHand": ("c_hand_fk{s}", "hand{s}")},
    {role: ("c_" + names[0], names[0]) for role, names in _fingers("{finger}{k}{{s}}").items()})

_VRM_FINGERS = {"Thumb": "Thumb", "Index": "Index", "Middle": "Middle", "Ring": "Ring", "Pinky": "Little"}
VROID = _family(
    "VRoid", ("L", "R"),
    {"Hips": ("J_Bip_C_Hips",), "Spine": ("J_Bip_C_Spine",), "Spine1": ("J_Bip_C_Chest",),
     "Spine2": ("J_Bip_C_UpperChest",), "Neck": ("J_Bip_C_Neck",), "Head": ("J_Bip_C_Head",)},
    {"LeftEye": ("J_Adj_{s}_FaceEye",), "LeftShoulder": ("J_Bip_{s}_Shoulder",), "LeftArm": ("J_Bip_{s}_UpperArm",),
     "LeftForeArm": ("J_Bip_{s}_LowerArm",), "LeftHand": ("J_Bip_{s}_Hand",)},
    _fingers("J_Bip_{{s}}_{finger}{k}", _VRM_FINGERS))

#: VRM humanoid bone names, as the VRM add-on can name an imported rig's bones; thumbs are
#: Proximal/Intermediate/Distal in VRM 0.x and Metacarpal/Proximal/Distal in 1.0.
_VRM_PHALANGES = ("Proximal", "Intermediate", "Distal")
_VRM_THUMB = (("Metacarpal", "Proximal"), ("Intermediate", "Proximal"), ("Distal",))
VRM_HUMANOID = _family(
    "VRM humanoid", ("left", "right"),
    {"Hips": ("hips",), "Spine": ("spine",), "Spine1": ("chest",), "Spine2": ("upperChest",),
     "Neck": ("neck",), "Head": ("head",)},
    {"LeftEye": ("{s}Eye",), "LeftShoulder": ("{s}Shoulder",), "LeftArm": ("{s}UpperArm",),
     "LeftForeArm": ("{s}LowerArm",), "LeftHand": ("{s}Hand",)},
    {f"LeftHand{f}{k}": tuple(f"{{s}}{_VRM_FINGERS[f]}{p}"
                              for p in (_VRM_THUMB[k - 1] if f == "Thumb" else (_VRM_PHALANGES[k - 1],)))
     for f in _FINGERS for k in (1, 2, 3)})

#: The VRM Add-on for Blender's humanoid armature names ('upper_arm.L', 'lower_arm.L', 'index.proximal.L'),
#: which VRM files it exports keep as node names; thumbs as in VRM_HUMANOID.
VRM_ADDON = _family(
    "VRM Add-on armature", (".L", ".R"),
    {"Hips": ("hips",), "Spine": ("spine",), "Spine1": ("chest",), "Spine2": ("upper_chest",), "Neck": ("neck",),
     "Head": ("head",)},
    {"LeftEye": ("eye{s}",), "LeftShoulder": ("shoulder{s}",), "LeftArm": ("upper_arm{s}",),
     "LeftForeArm": ("lower_arm{s}",), "LeftHand": ("hand{s}",)},
    {f"LeftHand{f}{k}": tuple(f"{_VRM_FINGERS[f].lower()}.{p.lower()}{{s}}"
                              for p in (_VRM_THUMB[k - 1] if f == "Thumb" else (_VRM_PHALANGES[k - 1],)))
     for f in _FINGERS for k in (1, 2, 3)})

CHARACTER_CREATOR = _family(
    "Character Creator", ("L", "R"),
    {"Hips": ("CC_Base_Hip",), "Spine": ("CC_Base_Waist",), "Spine1": ("CC_Base_Spine01",),
     "Spine2": ("CC_Base_Spine02",), "Neck": ("CC_Base_NeckTwist01",), "Head": ("CC_Base_Head",)},
    {"LeftEye": ("CC_Base_{s}_Eye",), "LeftShoulder": ("CC_Base_{s}_Clavicle",),
     "LeftArm": ("CC_Base_{s}_Upperarm",), "LeftForeArm": ("CC_Base_{s}_Forearm",), "LeftHand": ("CC_Base_{s}_Hand",)},
    _fingers("CC_Base_{{s}}_{finger}{k}", {f: "Mid" if f == "Middle" else f for f in _FINGERS}))

#: Rigify's deform bones alone, as a game export keeps them: the metarig's names behind "DEF-". A
#: whole Rigify rig has them too, driven by its controls, so this family is only tried on a rig
#: without Rigify's controls (`detect`).
RIGIFY_DEFORM = Family("Rigify deform", METARIG.sides,
                       {role: tuple("DEF-" + name for name in names) for role, names in METARIG.templates.items()})

_BIPED_FINGERS = {f: n for n, f in enumerate(_FINGERS)}
BIPED = _family(
    "3ds Max Biped", ("L", "R"),
    {"Hips": ("Pelvis",), "Spine": ("Spine",), "Spine1": ("Spine1",), "Spine2": ("Spine2",), "Neck": ("Neck",),
     "Head": ("Head",)},
    {"LeftShoulder": ("{s}Clavicle",), "LeftArm": ("{s}UpperArm",), "LeftForeArm": ("{s}Forearm",),
     "LeftHand": ("{s}Hand",)},
    {f"LeftHand{f}{k}": (f"{{s}}Finger{n}{'' if k == 1 else k - 1}",) for f, n in _BIPED_FINGERS.items()
     for k in (1, 2, 3)})

#: Every family, in the order that wins a tie.
FAMILIES = (MIXAMO, RIGIFY, UNREAL, AUTO_RIG_PRO, VROID, VRM_HUMANOID, VRM_ADDON, CHARACTER_CREATOR, METARIG,
            RIGIFY_DEFORM, BIPED)

#: Prefixes dropped before matching: Mixamo's ('mixamorig', 'mixamorig1_') and 3ds Max Biped's
#: ('Bip01 ', 'Bip001 ').
_PREFIX = re.compile(r"^(mixamorig\d*_?|bip0*1)")
#: A side suffix after a separator ('hand_l', 'hand.L', 'hand-l'), compared as '.l': UE names with
#: Blender's side suffixes ('upperarm.l', 'hand.l') are the UE family's 'upperarm_l', 'hand_l'.
_SIDE_SUFFIX = re.compile(r"[._-]([lr])$")


@lru_cache(maxsize=4096)
def name_key(name: str) -> str:
    """A bone name as matching compares it: namespace, spaces and a Mixamo or Biped prefix dropped, a side
    suffix's separator made '.', lower case (cached: detection compares every bone with every family's
    names on each Generate)."""
    return _SIDE_SUFFIX.sub(r".\1", _PREFIX.sub("", re.split(r"[:|]", name)[-1].lower().replace(" ", "")))


def _side_templates(family: Family, role: str) -> tuple[str, ...]:
    """The family's candidate names for a role, with the side token filled in."""
    if role.startswith("Right"):
        left = "Left" + role[len("Right"):]
        if left not in family.templates:
            return ()
        return tuple(t.format(s=family.sides[1]) for t in family.templates[left])
    return tuple(t.format(s=family.sides[0]) for t in family.templates.get(role, ()))


def family_roles(bone_names: Iterable[str], family: Family) -> dict[str, str]:
    """{role: bone name} for the roles the family finds among bone_names (the first candidate present that
    no earlier role took wins)."""
    by_key: dict[str, str] = {}
    for name in bone_names:
        by_key.setdefault(name_key(name), name)
    found: dict[str, str] = {}
    for role in ROLES:
        for template in _side_templates(family, role):
            bone = by_key.get(name_key(template))
            if bone is not None and bone not in found.values():
                found[role] = bone
                break
    return found


def detect(bone_names: Iterable[str], rigify: bool = False) -> tuple[Family, dict[str, str]]:
    """(family, {role: bone name}) of the family that recognises the most roles (ties: FAMILIES order).

    rigify: the rig was generated by Rigify (its rig_id), so it is Rigify whatever else it holds (an
    export skeleton copying its DEF- bones may match more roles). Otherwise Rigify is only a candidate
    when its arm FK controls are there: names like hand_fk.L alone (a custom rig's FK chain) are not Rigify.
    """
    family, roles = _detect(tuple(bone_names), rigify)
    return family, dict(roles)


@lru_cache(maxsize=16)
def _detect(bone_names: tuple[str, ...], rigify: bool) -> tuple[Family, dict[str, str]]:
    """`detect`, remembered per rig's bone names: matching every family takes a few milliseconds."""
    if rigify:
        return RIGIFY, family_roles(bone_names, RIGIFY)
    rigify_roles = family_roles(bone_names, RIGIFY)
    controlled = "LeftArm" in rigify_roles or "RightArm" in rigify_roles
    scored = [(len(family_roles(bone_names, f)), -i, f) for i, f in enumerate(FAMILIES)
              if not (f is RIGIFY_DEFORM and controlled) and not (f is RIGIFY and not controlled)]
    _, _, family = max(scored, key=lambda s: s[:2])
    return family, family_roles(bone_names, family)


def required_roles(arm: str) -> tuple[str, ...]:
    """Roles a gesture of `arm` cannot do without: a spine bone, the neck, the head and that arm (a collar
    bone it may lack: its turn goes to the upper arm, gesture.fold_missing)."""
    side = "Left" if arm == "LEFT" else "Right"
    return ("Neck", "Head") + tuple(side + part for part in ("Arm", "ForeArm", "Hand"))


def check_roles(rig_name: str, roles: Mapping[str, str], arm: str, family_name: str) -> None:
    """RLAnimateError listing the roles the gesture needs that `roles` lacks, and how to map them."""
    missing = [r for r in required_roles(arm) if r not in roles]
    if not any(r in roles for r in SPINE):
        missing.insert(0, "Spine")
    if missing:
        raise RLAnimateError(
            f"Armature {rig_name!r} has no bone for the roles {', '.join(missing)} (closest bone naming: "
            f"{family_name}). For a VRM character, click 'Bone Map from VRM File' in the RLAnimate panel and pick "
            "its .vrm file: the map the file carries names the bones. Otherwise map them: 'Save Bone Map' "
            "writes the detected map as a JSON file, with every role it could not find left empty; type your "
            "bone names for those and pick the file as Bone Map. Or rename those bones to Mixamo names.")


#: The note a saved bone-map file carries for whoever edits it.
BONE_MAP_NOTE = ('Each role names one bone of the armature; "" marks a role it could not find: type that bone\'s name, '
                 'or leave it "" (Spine or Spine1 or Spine2, Neck, Head and the gesturing arm\'s Arm, ForeArm and '
                 'Hand are needed; the rest are keyed where mapped). Then pick this file as Bone Map.')


def bone_map_json(family_name: str, roles: Mapping[str, str]) -> str:
    """The text of a bone-map file for {role: bone name}: every role, in ROLES order, "" for those `roles`
    lacks, so the user fills in names rather than typing roles."""
    return json.dumps({"family": family_name, "note": BONE_MAP_NOTE,
                       "bones": {r: roles.get(r, "") for r in ROLES}}, indent=2, ensure_ascii=False)


#: The largest bone-map file read (Save Bone Map writes about 2 KB).
MAX_BONE_MAP_BYTES = 1 << 20


def read_bone_map(text: str, bone_names: Iterable[str]) -> tuple[str, dict[str, str]]:
    """(family name, {role: bone name}) from a bone-map file's text, checked against the rig's bone names."""
    try:
        data = json.loads(text)
        bones = data["bones"]
        family_name = str(data.get("family", "Bone-map file"))
    except (ValueError, KeyError, TypeError, AttributeError, RecursionError):
        raise RLAnimateError('The bone-map file is not valid: it must be JSON like {"family": "...", '
                             '"bones": {"Spine": "my_spine", ...}}; save one from the panel to start.') from None
    if not isinstance(bones, dict) or not all(isinstance(b, str) for b in bones.values()):
        raise RLAnimateError('The bone-map file\'s "bones" must map role names to bone names, one name (a '
                             'string, "" for none) per role: correct the file, or save a new one from the panel.')
    bones = {role: bone for role, bone in bones.items() if bone}  # "": a role left unmapped
    shared = sorted(b for b, uses in Counter(bones.values()).items() if uses > 1)
    if shared:
        roles = [role for role, b in bones.items() if b == shared[0]]
        raise RLAnimateError(f"The bone-map file gives the bone {shared[0]!r} to the roles {', '.join(roles)}: "
                             "each role needs a bone of its own; correct the file.")
    unknown = sorted(set(bones) - set(ROLES))
    if unknown:
        raise RLAnimateError(f"The bone-map file names unknown roles {', '.join(unknown)}: use roles among "
                             f"{', '.join(ROLES[:12])}, ... (Mixamo bone names without prefix).")
    absent = sorted(str(b) for b in bones.values() if b not in set(bone_names))
    if absent:
        raise RLAnimateError(f"The bone-map file names bones the armature lacks: {', '.join(absent)}: "
                             "correct their names in the file or pick the matching armature.")
    return family_name, dict(bones)
