"""A VRM file's own humanoid map, read straight from its glTF JSON chunk, as core.rig_roles roles.

A .vrm is binary glTF. VRM 0.x keeps its map in `extensions.VRM.humanoid.humanBones`, a list of
{"bone": VRM bone name, "node": node index}; VRM 1.0 in `extensions.VRMC_vrm.humanoid.humanBones`,
a dict {VRM bone name: {"node": node index}}. Blender's glTF importer names each joint's bone after its
node (`Node_<index>` when unnamed; a name taken already gets ".001", ".002", ... in node order), so
the map names the imported rig's bones. A damaged or hostile file is refused with a message, never read
whole: only a regular file is opened (core/regular_file.py), only its JSON chunk is read, at most
MAX_JSON_BYTES of it, nested at most MAX_NESTING deep, and every field read is checked for its JSON type
before it is used.
"""
import json
import os
import re
import struct
from collections import Counter
from collections.abc import Iterable, Mapping
from typing import Any, TypeGuard

import numpy as np

from .errors import RLAnimateError
from .regular_file import open_regular

#: A real VRM's JSON chunk is tens to a few hundred kB (the UNAVI robot's: 26 kB); past this it is refused
#: before it is read (a 32 MB chunk took 6-12 s and 1.14 GB to parse).
MAX_JSON_BYTES = 2 * 1024 * 1024
#: glTF JSON nests about 7 deep (the robot's: 7); deeper is refused before parsing (1,000 deep raised
#: RecursionError in json).
MAX_NESTING = 64
#: VRM defines 55 human bones (1.0) and 53 (0.x); a map listing more than this is damaged.
MAX_HUMAN_BONES = 256
#: Blender's bone names hold at most 63 bytes (UTF-8); longer node names are cut there on import.
MAX_BONE_NAME_BYTES = 63

_CENTRE = {"hips": "Hips", "spine": "Spine", "chest": "Spine1", "upperChest": "Spine2", "neck": "Neck",
           "head": "Head"}
_SIDE = {"Eye": "Eye", "Shoulder": "Shoulder", "UpperArm": "Arm", "LowerArm": "ForeArm", "Hand": "Hand"}
_FINGERS = {"Index": "Index", "Middle": "Middle", "Ring": "Ring", "Little": "Pinky"}
_PHALANGES = ("Proximal", "Intermediate", "Distal")
#: A thumb's three bones: VRM 0.x names them like the other fingers, VRM 1.0 from the metacarpal.
_THUMB = {"0": _PHALANGES, "1": ("Metacarpal", "Proximal", "Distal")}
#: A file's path, as open() takes it.
FilePath = str | os.PathLike[str]


def _role_names(major: str) -> dict[str, str]:
    """{VRM bone name: role} for a VRM major version ("0" or "1")."""
    names = dict(_CENTRE)
    for vrm_side, side in (("left", "Left"), ("right", "Right")):
        names.update({vrm_side + part: side + role for part, role in _SIDE.items()})
        for finger, role in _FINGERS.items():
            names.update({f"{vrm_side}{finger}{p}": f"{side}Hand{role}{k}" for k, p in enumerate(_PHALANGES, 1)})
        names.update({f"{vrm_side}Thumb{p}": f"{side}HandThumb{k}" for k, p in enumerate(_THUMB[major], 1)})
    return names


#: {major version: {VRM bone name: role}}.
ROLE_OF = {major: _role_names(major) for major in _THUMB}
#: The family name the panel and messages show for a map read from a VRM file or the VRM add-on.
FAMILY = "VRM humanoid map"


def snake_case(vrm_name: str) -> str:
    """The VRM add-on's property name for a VRM 1.0 bone name: 'leftUpperArm' -> 'left_upper_arm'."""
    return re.sub(r"([A-Z])", r"_\1", vrm_name).lower()


def read_gltf_json(path: FilePath) -> dict[str, Any]:
    """The glTF JSON (a dict) of a binary glTF (.vrm, .glb) file, reading only its header and JSON chunk;
    its nodes, skins and extensions checked for their JSON types (`_check_gltf`)."""
    try:
        with open_regular(path) as handle:
            header = handle.read(20)
            if len(header) < 20 or header[:4] != b"glTF":
                raise RLAnimateError(f"{path} is not a VRM file (binary glTF): pick the character's .vrm file.")
            version, total, length, kind = struct.unpack("<III4s", header[4:])
            if version != 2 or kind != b"JSON":
                raise RLAnimateError(f"{path} is glTF version {version} with a first chunk {kind!r}, not glTF 2.0 "
                                     "with its JSON first: re-export the character as VRM.")
            if length > total - 20:
                raise RLAnimateError(f"{path} declares a JSON chunk of {length:,} bytes in a {total:,}-byte file: "
                                     "the file is damaged; re-export it.")
            if length > MAX_JSON_BYTES:
                raise RLAnimateError(f"{path} declares a JSON chunk of {length:,} bytes, more than a VRM's "
                                     f"({MAX_JSON_BYTES:,} at most): pick the character's .vrm file, or re-export it.")
            text = handle.read(length)
    except OSError as error:
        raise RLAnimateError(f"Cannot read the VRM file {path} ({error.strerror}): pick the character's .vrm "
                             "file.") from None
    if len(text) != length:
        raise RLAnimateError(f"{path} ends inside its JSON chunk ({len(text):,} of {length:,} bytes): the file is "
                             "truncated; copy or export it again.")
    depth = nesting(text)
    if depth > MAX_NESTING:
        raise RLAnimateError(f"The JSON chunk of {path} nests {depth:,} deep, more than a glTF's ({MAX_NESTING} at "
                             "most): the file is damaged; re-export it.")
    try:
        gltf = json.loads(text.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as error:
        raise RLAnimateError(f"The JSON chunk of {path} is not valid JSON ({error}): the file is damaged; "
                             "re-export it.") from None
    problem = _gltf_problem(gltf)
    if problem:
        raise RLAnimateError(f"The JSON chunk of {path} is not a glTF of a VRM ({problem}): the file is damaged; "
                             "re-export it.")
    checked: dict[str, Any] = gltf  # an object: _gltf_problem found none
    return checked


#: A JSON string (quotes and escapes inside it included): removed before brackets are counted.
_STRING = re.compile(rb'"[^"\\]*(?:\\.[^"\\]*)*"', re.DOTALL)
_OPENING, _CLOSING = np.frombuffer(b"[{", np.uint8), np.frombuffer(b"]}", np.uint8)


def nesting(text: bytes) -> int:
    """How deep the JSON text's arrays and objects nest (brackets inside strings left out)."""
    bare = np.frombuffer(_STRING.sub(b"", text), np.uint8)
    steps = np.isin(bare, _OPENING).astype(np.int64) - np.isin(bare, _CLOSING)
    return int(np.cumsum(steps).max(initial=0))


def _json_type(value: object) -> str:
    names = {bool: "a boolean", str: "a string", list: "a list", dict: "an object", type(None): "null"}
    return names.get(type(value), "a number")


def _is_index(value: object, count: int) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value < count


def _gltf_problem(gltf: object) -> str | None:
    """What is wrong with the types of the glTF fields this module reads (None: nothing)."""
    if not isinstance(gltf, dict):
        return f"the chunk holds {_json_type(gltf)}, not an object"
    for key, wanted in (("nodes", list), ("skins", list), ("extensions", dict)):
        if key in gltf and not isinstance(gltf[key], wanted):
            return f"its {key} is {_json_type(gltf[key])}, not {'a list' if wanted is list else 'an object'}"
    nodes = gltf.get("nodes", [])
    for index, node in enumerate(nodes):
        if not isinstance(node, dict):
            return f"node {index} is {_json_type(node)}, not an object"
        if "name" in node and not isinstance(node["name"], str):
            return f"node {index}'s name is {_json_type(node['name'])}, not a string"
    for index, skin in enumerate(gltf.get("skins", [])):
        joints = skin.get("joints", []) if isinstance(skin, dict) else None
        if not isinstance(joints, list):
            return f"skin {index} is {_json_type(skin)}, not an object" if joints is None else \
                f"skin {index}'s joints are {_json_type(joints)}, not a list"
        wrong = [joint for joint in joints if not _is_index(joint, len(nodes))]
        if wrong:
            return f"skin {index} lists the joint {json.dumps(wrong[0])[:20]}, not one of its {len(nodes)} nodes"
    return None


def humanoid_nodes(gltf: Mapping[str, Any], path: FilePath = "The file") -> tuple[str, dict[str, int]]:
    """(major version "0" or "1", {VRM bone name: node index}) of a glTF dict's VRM humanoid map (`path`:
    the file, for messages)."""
    extensions = gltf.get("extensions", {})
    if isinstance(extensions.get("VRMC_vrm"), dict):
        major, bones = "1", _dig(extensions["VRMC_vrm"], "VRMC_vrm", path)
        if not isinstance(bones, dict):
            raise RLAnimateError(f"The VRMC_vrm humanoid.humanBones of {path} is not a dict of bones: the VRM 1.0 "
                                 "file is damaged; re-export it.")
        pairs = [(name, entry.get("node") if isinstance(entry, dict) else None) for name, entry in bones.items()]
    elif isinstance(extensions.get("VRM"), dict):
        major, bones = "0", _dig(extensions["VRM"], "VRM", path)
        if not isinstance(bones, list):
            raise RLAnimateError(f"The VRM humanoid.humanBones of {path} is not a list of bones: the VRM 0.x file "
                                 "is damaged; re-export it.")
        pairs = [(entry.get("bone"), entry.get("node")) if isinstance(entry, dict) else (None, None)
                 for entry in bones]
    else:
        raise RLAnimateError(f"{path} has no VRM humanoid (neither the VRMC_vrm nor the VRM extension): it is a "
                             "plain glTF, not a VRM; map its bones with a bone-map file instead.")
    if len(pairs) > MAX_HUMAN_BONES:
        raise RLAnimateError(f"The VRM humanoid of {path} lists {len(pairs)} bones (VRM defines 55): the file is "
                             "damaged; re-export it.")
    count = len(gltf.get("nodes", []))
    out: dict[str, int] = {}
    for name, node in pairs:
        if not isinstance(name, str) or not _is_index(node, count):
            raise RLAnimateError(f"The VRM humanoid of {path} maps {str(name)[:40]!r} to node {str(node)[:20]}, "
                                 f"not one of its {count} nodes: the file is damaged; re-export it.")
        out[name] = node
    return major, out


def _dig(extension: Mapping[str, Any], label: str, path: FilePath) -> Any:
    humanoid = extension.get("humanoid")
    if not isinstance(humanoid, dict) or "humanBones" not in humanoid:
        raise RLAnimateError(f"The {label} extension of {path} has no humanoid.humanBones: it is not a humanoid "
                             "VRM; map its bones with a bone-map file instead.")
    return humanoid["humanBones"]


def imported_bone_names(gltf: Mapping[str, Any]) -> list[str]:
    """(nodes,) the bone name Blender's glTF importer gives each node: its name cut to 63 bytes, or
    'Node_<index>', with ".001", ".002", ... on a name an earlier joint (a node of a skin) took."""
    joints = {j for skin in gltf.get("skins", []) for j in skin.get("joints", [])}
    taken: set[str] = set()
    out: list[str] = []
    for index, node in enumerate(gltf.get("nodes", [])):
        unique = base = _cut(node.get("name") or f"Node_{index}")
        k = 0
        while index in joints and unique in taken:
            k += 1
            unique = f"{_cut(base, MAX_BONE_NAME_BYTES - 4)}.{k:03d}"
        if index in joints:
            taken.add(unique)
        out.append(unique)
    return out


def _cut(name: str, limit: int = MAX_BONE_NAME_BYTES) -> str:
    return name.encode("utf-8")[:limit].decode("utf-8", "ignore")


def roles_from_map(major: str, bone_of: Mapping[str, str]) -> dict[str, str]:
    """{role: bone name} from a VRM humanoid map {VRM bone name: bone name} of major version "0" or "1";
    VRM bones without a role (legs, toes, jaw) are left out."""
    names = ROLE_OF[major]
    return {names[vrm]: bone for vrm, bone in bone_of.items() if vrm in names and bone}


def file_map(path: FilePath) -> dict[str, str]:
    """{role: bone name} of the armature Blender's glTF importer makes from the VRM file at `path`: its
    humanoid map, read and checked (a bone given to two roles is refused, as in a bone-map file)."""
    gltf = read_gltf_json(path)
    major, nodes = humanoid_nodes(gltf, path)
    names = imported_bone_names(gltf)
    roles = roles_from_map(major, {vrm: names[node] for vrm, node in nodes.items()})
    check_one_role_per_bone(roles, f"The VRM file {path}", "export the VRM again")
    return roles


def check_one_role_per_bone(roles: Mapping[str, str], source: str, then: str) -> None:
    """RLAnimateError when a VRM humanoid map (`source`, for the message) gives one bone two roles, as a
    bone-map file's is; `then`: what to do after correcting the map."""
    shared = sorted(bone for bone, uses in Counter(roles.values()).items() if uses > 1)
    if shared:
        given = [role for role, bone in roles.items() if bone == shared[0]]
        raise RLAnimateError(f"{source} gives the bone {shared[0]!r} to the roles {', '.join(given)}: each role "
                             f"needs a bone of its own. Correct the humanoid map (VRM add-on: Humanoid panel) and "
                             f"{then}, or map the bones with a bone-map file.")


def check_bones(roles: Mapping[str, str], bone_names: Iterable[str], path: FilePath,
                rig_name: str = "the armature") -> None:
    """RLAnimateError when the VRM file's map `roles` names bones the armature (`bone_names`) lacks."""
    present = set(bone_names)
    absent = sorted(bone for bone in roles.values() if bone not in present)
    if absent:
        shown = ", ".join(absent[:3]) + (f" and {len(absent) - 3} more" if len(absent) > 3 else "")
        raise RLAnimateError(f"The VRM file {path} names bones {rig_name} lacks: {shown}. Pick the VRM file this "
                             "armature was imported from, or, if its bones were renamed, save its bone map from "
                             "the panel and correct the names.")


def file_roles(path: FilePath, bone_names: Iterable[str], rig_name: str = "the armature") -> dict[str, str]:
    """{role: bone name} of an armature imported from the VRM file at path, checked against its bone names."""
    roles = file_map(path)
    check_bones(roles, bone_names, path, rig_name)
    return roles
