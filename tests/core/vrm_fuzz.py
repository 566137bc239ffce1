"""Seeded mutations of a real VRM file's header and JSON chunk, for the extension's VRM reader.

`mutations(original, rng)` yields (kind, bytes) without end; `outcome(path, reference)` reads a file
through the extension's reader (core.vrm.file_roles, as Generate and "Bone Map from VRM File" read the
file an armature was imported from) and names what happened. Shared by tests/core/test_vrm_fuzz.py and
benchmarks/vrm_fuzz_benchmark.py.

Kinds:
    header        a field of the 20-byte header (magic, version, total length, chunk length, chunk type)
                  set to an edge value or random bytes
    truncate      the file cut short, in its header, its JSON chunk or its binary chunk
    chunk_bytes   bytes of the JSON chunk changed, inserted or deleted (bit flips, random bytes), the
                  chunk length kept or fixed to match
    json_text     characters of the JSON text replaced by JSON syntax ({}[]:," digits, true, null...)
    json_value    a value the reader uses (extensions, the humanoid, its bones, their nodes and names,
                  nodes, node names, skins, joints) replaced by an edge value (1e300, NaN, huge integers,
                  strings, lists, objects, booleans, null) or removed, in valid JSON
    humanoid      the humanoid map rewritten as a damaged exporter might: a bone's node moved (onto another
                  bone's: one bone in two roles; out of range), a VRM bone renamed or listed twice, entries
                  dropped or shuffled, the map turned into VRM 1.0's form, node names changed (repeated,
                  empty, 200 characters, non-ASCII), joints dropped or repeated
    nesting       a value nested 63 to 100,000 deep inserted, or strings full of brackets and escapes
    size          the chunk padded to 2 MiB, just over, or 32 MiB; thousands of extra nodes
"""
import json
import struct

import numpy as np

import fuzz_json
from rlanimate_addon.core import vrm
from rlanimate_addon.core.errors import RLAnimateError

KINDS = ("header", "truncate", "chunk_bytes", "json_text", "json_value", "humanoid", "nesting", "size")
#: Outcomes the reader may have: refused with an RLAnimateError, the original map, or a changed map read
#: exactly as the changed JSON says, one bone per role. Anything else fails.
ACCEPTED = ("refused", "identical", "valid other map")
_EDGE_FIELDS = (0, 1, 2, 3, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF, 2 ** 21, 2 ** 21 + 1, 2 ** 25)
_EDGE_VALUES = (1e300, -1e300, float("inf"), float("nan"), 10 ** 400, -1, 0, 1, 2.5, 5, True, False, None, "", "abc",
                "leftHand", [], {}, [1, 2], [[[]]], {"node": 3}, {"bone": "hips", "node": 1}, "x" * 300, "ü" * 40)
_JSON_CHARACTERS = ('{', '}', '[', ']', ':', ',', '"', '0', '1', '9', '-', '.', 'e', ' ', 'n', 't', '\\')
_DEPTHS = (63, 64, 65, 100, 1000, 100_000)
_PADDING = (2 * 2 ** 20 - 64, 2 * 2 ** 20, 2 * 2 ** 20 + 4, 32 * 2 ** 20)


class Reference:
    """The unmutated file: its bytes, the bone names its import has, and the roles it maps."""

    def __init__(self, path):
        self.data = path.read_bytes()
        self.gltf = json.loads(_chunk(self.data))
        self.bone_names = vrm.imported_bone_names(self.gltf)
        self.roles = vrm.file_roles(str(path), self.bone_names)


def _chunk(data):
    return data[20:20 + struct.unpack_from("<I", data, 12)[0]]


def outcome(path, reference):
    """What the extension's reader made of the file at `path`, read for the reference's armature."""
    try:
        roles = vrm.file_roles(str(path), reference.bone_names, "the armature")
    except RLAnimateError:
        return "refused"
    except Exception as error:  # noqa: BLE001  (what the fuzz looks for)
        return f"other exception {type(error).__name__}: {str(error)[:200]}"
    if roles == reference.roles:
        return "identical"
    if len(set(roles.values())) < len(roles):
        return f"a map giving one bone two roles: {roles}"
    expected = _as_the_json_says(path.read_bytes())
    return "valid other map" if roles == expected else f"changed map (read {roles}, the JSON says {expected})"


def _as_the_json_says(data):
    """{role: bone name} of a file's JSON chunk, read directly (the oracle for a changed map): each VRM bone
    of the humanoid onto its node's imported bone name."""
    gltf = json.loads(_chunk(data))
    extensions = gltf.get("extensions", {})
    if "VRMC_vrm" in extensions:
        major, pairs = "1", [(name, e["node"]) for name, e in extensions["VRMC_vrm"]["humanoid"]["humanBones"].items()]
    else:
        major, pairs = "0", [(e["bone"], e["node"]) for e in extensions["VRM"]["humanoid"]["humanBones"]]
    joints = {j for skin in gltf.get("skins", []) for j in skin.get("joints", [])}
    names, taken = [], set()
    for index, node in enumerate(gltf.get("nodes", [])):
        name = (node.get("name") or f"Node_{index}").encode()[:63].decode("utf-8", "ignore")
        base, k = name, 0
        while index in joints and name in taken:
            k += 1
            name = f"{base.encode()[:59].decode('utf-8', 'ignore')}.{k:03d}"
        taken |= {name} if index in joints else set()
        names.append(name)
    roles = vrm.ROLE_OF[major]
    return {roles[bone]: names[node] for bone, node in dict(pairs).items() if bone in roles}


def mutations(original, rng):
    """(kind, bytes) of the original file, one mutation each, without end."""
    gltf = json.loads(_chunk(original))
    while True:
        kind = KINDS[int(rng.integers(len(KINDS)))]
        yield kind, _MUTATE[kind](original, gltf, rng)


def _pick(options, rng):
    return options[int(rng.integers(len(options)))]


def _glb(original, text, length=None):
    """The original file with JSON chunk `text` (bytes, space-padded to 4), its binary chunk kept."""
    text += b" " * (-len(text) % 4)
    rest = original[20 + struct.unpack_from("<I", original, 12)[0]:]
    length = len(text) if length is None else length
    return b"glTF" + struct.pack("<II", 2, 20 + len(text) + len(rest)) + struct.pack("<I4s", length, b"JSON") \
        + text + rest


def _header(original, gltf, rng):
    data = bytearray(original)
    at = _pick((0, 4, 8, 12, 16), rng)
    if rng.random() < 0.7:
        data[at:at + 4] = struct.pack("<I", _pick(_EDGE_FIELDS, rng))
    else:
        data[at:at + 4] = rng.integers(0, 256, 4, dtype=np.uint8).tobytes()
    return bytes(data)


def _truncate(original, gltf, rng):
    length = struct.unpack_from("<I", original, 12)[0]
    end = _pick((int(rng.integers(0, 21)), int(rng.integers(20, 20 + length)),
                 int(rng.integers(20 + length, len(original)))), rng)
    return original[:end]


def _chunk_bytes(original, gltf, rng):
    text = bytearray(_chunk(original))
    for _ in range(int(rng.integers(1, 9))):
        at = int(rng.integers(len(text)))
        change = rng.random()
        if change < 0.4:
            text[at] ^= 1 << int(rng.integers(8))
        elif change < 0.7:
            text[at] = int(rng.integers(256))
        elif change < 0.85:
            text.insert(at, int(rng.integers(256)))
        else:
            del text[at]
    keep = rng.random() < 0.3  # the header's length left as it was
    return _glb(original, bytes(text), struct.unpack_from("<I", original, 12)[0] if keep else None)


def _json_text(original, gltf, rng):
    text = list(_chunk(original).decode())
    for _ in range(int(rng.integers(1, 4))):
        text[int(rng.integers(len(text)))] = _pick(_JSON_CHARACTERS, rng)
    return _glb(original, "".join(text).encode())


def _paths(gltf, rng):
    """A path (keys and indices) to a value the reader uses."""
    bones = len(gltf["extensions"]["VRM"]["humanoid"]["humanBones"])
    node, bone = int(rng.integers(len(gltf["nodes"]))), int(rng.integers(bones))
    human = ("extensions", "VRM", "humanoid", "humanBones")
    return _pick((("extensions",), ("extensions", "VRM"), ("extensions", "VRM", "humanoid"), human,
                  human + (bone,), human + (bone, "node"), human + (bone, "bone"), ("nodes",), ("nodes", node),
                  ("nodes", node, "name"), ("skins",), ("skins", 0), ("skins", 0, "joints"),
                  ("skins", 0, "joints", int(rng.integers(len(gltf["skins"][0]["joints"])))), ()), rng)


def _json_value(original, gltf, rng):
    changed = json.loads(json.dumps(gltf))
    changed = fuzz_json.set_or_remove(changed, _paths(changed, rng), rng, _EDGE_VALUES)
    return _glb(original, json.dumps(changed).encode())


def _humanoid(original, gltf, rng):
    changed = json.loads(json.dumps(gltf))
    bones = changed["extensions"]["VRM"]["humanoid"]["humanBones"]
    nodes = changed["nodes"]
    for _ in range(int(rng.integers(1, 4))):
        entry = bones[int(rng.integers(len(bones)))]
        change = int(rng.integers(7))
        if change == 0:  # onto another bone's node, or anywhere
            entry["node"] = _pick((bones[int(rng.integers(len(bones)))]["node"], int(rng.integers(-2, len(nodes) + 3))),
                                  rng)
        elif change == 1:  # renamed, or a name listed twice
            entry["bone"] = _pick((bones[int(rng.integers(len(bones)))]["bone"], "leftToes", "tail", "LeftHand"), rng)
        elif change == 2:
            bones.remove(entry)
        elif change == 3:
            rng.shuffle(bones)
        elif change == 4:
            node = nodes[int(rng.integers(len(nodes)))]
            node["name"] = _pick((nodes[int(rng.integers(len(nodes)))].get("name", ""), "", "n" * 200, "腕.L"), rng)
        elif change == 5:
            joints = changed["skins"][0]["joints"]
            if rng.random() < 0.5:  # a joint repeated
                joints.insert(int(rng.integers(len(joints))), joints[int(rng.integers(len(joints)))])
            else:
                joints.pop(int(rng.integers(len(joints))))
        else:
            bones.append(dict(entry))
    if rng.random() < 0.2:  # as VRM 1.0: humanBones a dict {name: {"node": n}}
        changed["extensions"]["VRMC_vrm"] = {"humanoid": {"humanBones": {e.get("bone", "?"): {"node": e.get("node")}
                                                                         for e in bones}}}
        del changed["extensions"]["VRM"]
    return _glb(original, json.dumps(changed).encode())


def _nesting(original, gltf, rng):
    depth = _pick(_DEPTHS, rng)
    if rng.random() < 0.3:  # brackets and escapes inside a string, which nest nothing
        nested = json.dumps("[{\\\"" * depth)
    else:
        opening, closing = _pick((("[", "]"), ('{"a":', "}")), rng)
        nested = opening * depth + "0" + closing * depth
    changed = json.loads(json.dumps(gltf))
    holder = _pick((changed, changed["extensions"]["VRM"]["humanoid"], changed["nodes"][0]), rng)
    holder["extras"] = "NESTED"
    return _glb(original, json.dumps(changed).replace('"NESTED"', nested).encode())


def _size(original, gltf, rng):
    if rng.random() < 0.6:
        text = _chunk(original).rstrip()
        return _glb(original, text + b" " * max(0, _pick(_PADDING, rng) - len(text)))
    changed = json.loads(json.dumps(gltf))
    changed["nodes"] += [{"name": f"extra{k}"} for k in range(int(_pick((1000, 10_000, 40_000), rng)))]
    return _glb(original, json.dumps(changed).encode())


_MUTATE = {"header": _header, "truncate": _truncate, "chunk_bytes": _chunk_bytes, "json_text": _json_text,
           "json_value": _json_value, "humanoid": _humanoid, "nesting": _nesting, "size": _size}
