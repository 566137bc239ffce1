"""A VRM file's own humanoid map, read straight from its glTF JSON chunk, as core.rig_roles roles.

A .vrm is binary glTF. VRM 0.x keeps its map in `extensions.VRM.humanoid.humanBones`, a list of
{"bone": VRM bone name, "node": node index}; VRM 1.0 in `extensions.VRMC_vrm.humanoid.humanBones`,
a dict {VRM bone name: {"node": node index}}. Blender's glTF importer names each joint's bone after its
node (`Node_<index>` when unnamed; a name taken already gets ".001", ".002", ... in node order), so
the map names the imported rig's bones. Every length read is bounded: a damaged or hostile file is
refused with a message, never read whole into memory.
"""
import json
import re
import struct

from .errors import RLAnimateError

#: The JSON chunk a VRM's humanoid map lives in is a few hundred kB; anything past this is refused.
MAX_JSON_BYTES = 32 * 1024 * 1024
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


def _role_names(major):
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


def snake_case(vrm_name):
    """The VRM add-on's property name for a VRM 1.0 bone name: 'leftUpperArm' -> 'left_upper_arm'."""
    return re.sub(r"([A-Z])", r"_\1", vrm_name).lower()


def read_gltf_json(path):
    """The glTF JSON (a dict) of a binary glTF (.vrm, .glb) file, reading only its header and JSON chunk."""
    try:
        with open(path, "rb") as handle:
            header = handle.read(20)
            if len(header) < 20 or header[:4] != b"glTF":
                raise RLAnimateError(f"{path} is not a VRM file (binary glTF): pick the character's .vrm file.")
            version, total, length, kind = struct.unpack("<III4s", header[4:])
            if version != 2 or kind != b"JSON":
                raise RLAnimateError(f"{path} is glTF version {version} with a first chunk {kind!r}, not glTF 2.0 "
                                     "with its JSON first: re-export the character as VRM.")
            if length > min(MAX_JSON_BYTES, total - 20):
                raise RLAnimateError(f"{path} declares a JSON chunk of {length:,} bytes in a {total:,}-byte file "
                                     f"(at most {MAX_JSON_BYTES:,} are read): the file is damaged; re-export it.")
            text = handle.read(length)
    except OSError as error:
        raise RLAnimateError(f"Cannot read the VRM file {path} ({error.strerror}): pick an existing file.") from None
    if len(text) != length:
        raise RLAnimateError(f"{path} ends inside its JSON chunk ({len(text):,} of {length:,} bytes): the file is "
                             "truncated; copy or export it again.")
    try:
        gltf = json.loads(text.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as error:
        raise RLAnimateError(f"The JSON chunk of {path} is not valid JSON ({error}): the file is damaged; "
                             "re-export it.") from None
    if not isinstance(gltf, dict):
        raise RLAnimateError(f"The JSON chunk of {path} is not a glTF object: the file is damaged; re-export it.")
    return gltf


def humanoid_nodes(gltf):
    """(major version "0" or "1", {VRM bone name: node index}) of a glTF dict's VRM humanoid map."""
    extensions = gltf.get("extensions")
    extensions = extensions if isinstance(extensions, dict) else {}
    if isinstance(extensions.get("VRMC_vrm"), dict):
        major, bones = "1", _dig(extensions["VRMC_vrm"], "VRMC_vrm")
        if not isinstance(bones, dict):
            raise RLAnimateError("The file's VRMC_vrm humanoid.humanBones is not a dict of bones: the VRM 1.0 file "
                                 "is damaged; re-export it.")
        pairs = [(name, entry.get("node") if isinstance(entry, dict) else None) for name, entry in bones.items()]
    elif isinstance(extensions.get("VRM"), dict):
        major, bones = "0", _dig(extensions["VRM"], "VRM")
        if not isinstance(bones, list):
            raise RLAnimateError("The file's VRM humanoid.humanBones is not a list of bones: the VRM 0.x file is "
                                 "damaged; re-export it.")
        pairs = [(entry.get("bone"), entry.get("node")) if isinstance(entry, dict) else (None, None)
                 for entry in bones]
    else:
        raise RLAnimateError("The file has no VRM humanoid (neither the VRMC_vrm nor the VRM extension): it is a "
                             "plain glTF, not a VRM; map its bones with a bone-map file instead.")
    if len(pairs) > MAX_HUMAN_BONES:
        raise RLAnimateError(f"The file's VRM humanoid lists {len(pairs)} bones (VRM defines 55): the file is "
                             "damaged; re-export it.")
    nodes = gltf.get("nodes")
    count = len(nodes) if isinstance(nodes, list) else 0
    out = {}
    for name, node in pairs:
        if not isinstance(name, str) or isinstance(node, bool) or not isinstance(node, int) or not 0 <= node < count:
            raise RLAnimateError(f"The file's VRM humanoid maps {str(name)[:40]!r} to node {str(node)[:20]}, not one "
                                 f"of its {count} nodes: the file is damaged; re-export it.")
        out[name] = node
    return major, out


def _dig(extension, label):
    humanoid = extension.get("humanoid")
    if not isinstance(humanoid, dict) or "humanBones" not in humanoid:
        raise RLAnimateError(f"The file's {label} extension has no humanoid.humanBones: it is not a humanoid "
                             "VRM; map its bones with a bone-map file instead.")
    return humanoid["humanBones"]


def imported_bone_names(gltf):
    """(nodes,) the bone name Blender's glTF importer gives each node: its name cut to 63 bytes, or
    'Node_<index>', with ".001", ".002", ... on a name an earlier joint (a node of a skin) took."""
    joints = set()
    for skin in gltf.get("skins") or ():
        listed = skin.get("joints") if isinstance(skin, dict) else None
        joints.update(j for j in (listed if isinstance(listed, list) else ()) if isinstance(j, int))
    taken, out = set(), []
    for index, node in enumerate(gltf.get("nodes") or ()):
        name = node.get("name") if isinstance(node, dict) else None
        unique = base = _cut(name if isinstance(name, str) and name else f"Node_{index}")
        k = 0
        while index in joints and unique in taken:
            k += 1
            unique = f"{_cut(base, MAX_BONE_NAME_BYTES - 4)}.{k:03d}"
        if index in joints:
            taken.add(unique)
        out.append(unique)
    return out


def _cut(name, limit=MAX_BONE_NAME_BYTES):
    return name.encode("utf-8")[:limit].decode("utf-8", "ignore")


def roles_from_map(major, bone_of):
    """{role: bone name} from a VRM humanoid map {VRM bone name: bone name} of major version "0" or "1";
    VRM bones without a role (legs, toes, jaw) are left out."""
    names = ROLE_OF[major]
    return {names[vrm]: bone for vrm, bone in bone_of.items() if vrm in names and bone}


def file_roles(path, bone_names, rig_name="the armature"):
    """{role: bone name} of an armature imported from the VRM file at path, checked against its bone names."""
    gltf = read_gltf_json(path)
    major, nodes = humanoid_nodes(gltf)
    names = imported_bone_names(gltf)
    roles = roles_from_map(major, {vrm: names[node] for vrm, node in nodes.items()})
    present = set(bone_names)
    absent = sorted(bone for bone in roles.values() if bone not in present)
    if absent:
        shown = ", ".join(absent[:3]) + (f" and {len(absent) - 3} more" if len(absent) > 3 else "")
        raise RLAnimateError(f"The VRM file {path} names bones {rig_name} lacks: {shown}. Pick the VRM file this "
                             "armature was imported from, or, if its bones were renamed, save its bone map from "
                             "the panel and correct the names.")
    return roles
