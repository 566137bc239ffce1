"""core.vrm: a VRM file's humanoid map (0.x and 1.0) read from its JSON chunk, bounded, with clear refusals."""
import json
import struct

import pytest

from rlanimate_addon.core import rig_roles, vrm
from rlanimate_addon.core.errors import RLAnimateError

NODES = [{"name": n} for n in ("root", "hips", "spine", "chest", "neck", "head", "shoulder.L", "upper_arm.L",
                                "lower_arm.L", "hand.L", "thumb.a.L", "thumb.b.L", "thumb.c.L")]
VRM0 = {"bone": "hips", "node": 1}, {"bone": "spine", "node": 2}, {"bone": "chest", "node": 3}, \
    {"bone": "neck", "node": 4}, {"bone": "head", "node": 5}, {"bone": "leftShoulder", "node": 6}, \
    {"bone": "leftUpperArm", "node": 7}, {"bone": "leftLowerArm", "node": 8}, {"bone": "leftHand", "node": 9}, \
    {"bone": "leftThumbProximal", "node": 10}, {"bone": "leftThumbIntermediate", "node": 11}, \
    {"bone": "leftThumbDistal", "node": 12}, {"bone": "leftUpperLeg", "node": 0}


def glb(gltf, binary=b"\0\0\0\0"):
    """A binary glTF file's bytes: header, JSON chunk (space-padded) and a BIN chunk; gltf: a dict, or the
    JSON text."""
    text = (gltf if isinstance(gltf, str) else json.dumps(gltf)).encode()  # str: the JSON text itself
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I4s", len(text), b"JSON") + text
            + struct.pack("<I4s", len(binary), b"BIN\0") + binary)


def vrm1_of(bones):
    """The VRM 1.0 humanBones dict of VRM 0.x entries: thumbs renamed as VRM 1.0 names them."""
    rename = {"ThumbProximal": "ThumbMetacarpal", "ThumbIntermediate": "ThumbProximal"}
    out = {}
    for entry in bones:
        name = entry["bone"]
        for old, new in rename.items():
            if name.endswith(old):
                name = name[:-len(old)] + new
        out[name] = {"node": entry["node"]}
    return out


def _write(tmp_path, data, name="x.vrm"):
    path = tmp_path / name
    path.write_bytes(data)
    return str(path)


def test_vrm0_and_vrm1_maps_give_the_same_roles(tmp_path):
    v0 = _write(tmp_path, glb({"nodes": NODES, "extensions": {"VRM": {"humanoid": {"humanBones": list(VRM0)}}}}))
    v1 = _write(tmp_path, glb({"nodes": NODES, "extensions": {"VRMC_vrm": {"specVersion": "1.0", "humanoid": {
        "humanBones": vrm1_of(VRM0)}}}}), "y.vrm")
    names = [n["name"] for n in NODES]
    roles0, roles1 = vrm.file_roles(v0, names), vrm.file_roles(v1, names)
    assert roles0 == roles1
    assert roles0["Spine1"] == "chest" and roles0["LeftArm"] == "upper_arm.L" and roles0["LeftForeArm"] == "lower_arm.L"
    assert [roles0[f"LeftHandThumb{k}"] for k in (1, 2, 3)] == ["thumb.a.L", "thumb.b.L", "thumb.c.L"]
    assert set(roles0) <= set(rig_roles.ROLES) and "root" not in roles0.values()  # the leg has no role


def test_imported_names_follow_the_gltf_importer():
    long_name = "x" * 80
    gltf = {"nodes": [{"name": "bone"}, {}, {"name": "bone"}, {"name": long_name}, {"name": "mesh"}, {"name": "mesh"}],
            "skins": [{"joints": [0, 1, 2, 3]}]}
    names = vrm.imported_bone_names(gltf)
    assert names[:3] == ["bone", "Node_1", "bone.001"]
    assert names[3] == "x" * 63 and names[4:] == ["mesh", "mesh"]  # meshes are objects: no bone-name clash


@pytest.mark.parametrize("case, message", [
    ("not glTF", "is not a VRM file"),
    ("glTF 1", "not glTF 2.0"),
    ("huge chunk", "declares a JSON chunk of 2,147,483,648 bytes in a"),
    ("chunk larger than a VRM's", "declares a JSON chunk of 33,554,432 bytes, more than a VRM's .2,097,152"),
    ("nested 1,000 deep", "nests 1,001 deep, more than a glTF's .64"),
    ("skins a number", "its skins is a number, not a list"),
    ("node a string", "node 2 is a string, not an object"),
    ("name a number", "node 1's name is a number, not a string"),
    ("joint out of range", "skin 0 lists the joint 13, not one of its 13 nodes"),
    ("joint null", "skin 0 lists the joint null"),
    ("one bone in two roles", "gives the bone 'upper_arm.L' to the roles LeftArm, LeftForeArm: each role needs"),
    ("truncated", "ends inside its JSON chunk"),
    ("bad JSON", "is not valid JSON"),
    ("plain glTF", "it is a plain glTF, not a VRM"),
    ("no humanoid", "has no humanoid.humanBones"),
    ("node out of range", "not one of its 13 nodes"),
    ("too many bones", "lists 300 bones"),
    ("wrong type", "is not a list of bones"),
    ("bone the rig lacks", "names bones the armature lacks: hand.L"),
    ("absent file", "Cannot read the VRM file"),
])
def test_bad_files_are_refused_with_what_is_wrong(tmp_path, case, message):
    good = {"nodes": NODES, "extensions": {"VRM": {"humanoid": {"humanBones": list(VRM0)}}}}
    names = [n["name"] for n in NODES]
    data = glb(good)
    if case == "not glTF":
        data = b"PK\x03\x04" + data[4:]
    elif case == "glTF 1":
        data = data[:4] + struct.pack("<I", 1) + data[8:]
    elif case == "huge chunk":
        data = data[:12] + struct.pack("<I", 2 ** 31) + data[16:]
    elif case == "chunk larger than a VRM's":
        data = glb(good) + b" " * 2 ** 25  # a 32 MiB chunk in a file that holds it
        data = data[:8] + struct.pack("<II", len(data), 2 ** 25) + data[16:]
    elif case == "nested 1,000 deep":
        data = glb(json.dumps(good)[:-1] + ', "extras": ' + "[" * 1000 + "]" * 1000 + "}")
    elif case == "skins a number":
        data = glb({**good, "skins": 5})
    elif case == "node a string":
        data = glb({**good, "nodes": NODES[:2] + ["spine"] + NODES[3:]})
    elif case == "name a number":
        data = glb({**good, "nodes": NODES[:1] + [{"name": 7}] + NODES[2:]})
    elif case == "joint out of range":
        data = glb({**good, "skins": [{"joints": [0, 1, 13]}]})
    elif case == "joint null":
        data = glb({**good, "skins": [{"joints": [0, None]}]})
    elif case == "one bone in two roles":
        bones = [dict(entry, node=7) if entry["bone"] == "leftLowerArm" else entry for entry in VRM0]
        data = glb({"nodes": NODES, "extensions": {"VRM": {"humanoid": {"humanBones": bones}}}})
    elif case == "truncated":
        data = data[:40]
        data = data[:8] + struct.pack("<I", len(data) + 10 ** 6) + data[12:]
    elif case == "bad JSON":
        data = glb(good).replace(b'"nodes"', b'{nodes"')
    elif case == "plain glTF":
        data = glb({"nodes": NODES})
    elif case == "no humanoid":
        data = glb({"nodes": NODES, "extensions": {"VRM": {"meta": {}}}})
    elif case == "node out of range":
        data = glb(
            {"nodes": NODES, "extensions": {"VRM": {"humanoid": {"humanBones": [{"bone": "hips", "node": 99}]}}}}
        )
    elif case == "too many bones":
        data = glb({"nodes": NODES, "extensions": {"VRM": {"humanoid": {"humanBones": [VRM0[0]] * 300}}}})
    elif case == "wrong type":
        data = glb({"nodes": NODES, "extensions": {"VRM": {"humanoid": {"humanBones": {"hips": 1}}}}})
    elif case == "bone the rig lacks":
        names.remove("hand.L")
    path = str(tmp_path / "absent.vrm") if case == "absent file" else _write(tmp_path, data)
    with pytest.raises(RLAnimateError, match=message):
        vrm.file_roles(path, names, "the armature")


def test_only_the_json_chunk_is_read(tmp_path, monkeypatch):
    """A file is read up to its JSON chunk: a large binary chunk after it is never loaded."""
    path = _write(tmp_path, glb({"nodes": NODES, "extensions": {"VRM": {"humanoid": {"humanBones": list(VRM0)}}}},
                                binary=b"\0" * (8 * 1024 * 1024)))
    read = []

    class Counting:
        def __init__(self, handle):
            self.handle = handle

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.handle.close()

        def read(self, size=-1):
            assert size >= 0, "the reader must never read a file to its end"
            data = self.handle.read(size)
            read.append(len(data))
            return data
    opened = vrm.open_regular
    monkeypatch.setattr(vrm, "open_regular", lambda p: Counting(opened(p)))
    assert vrm.read_gltf_json(path)["nodes"] == NODES
    assert 0 < sum(read) < 64 * 1024


def test_vrm_addon_property_names():
    assert vrm.snake_case("leftThumbMetacarpal") == "left_thumb_metacarpal"
    assert vrm.snake_case("upperChest") == "upper_chest"
    assert vrm.ROLE_OF["1"]["leftThumbMetacarpal"] == "LeftHandThumb1"
    assert vrm.ROLE_OF["0"]["leftThumbProximal"] == "LeftHandThumb1"
    assert vrm.ROLE_OF["1"]["leftThumbProximal"] == "LeftHandThumb2"
    assert vrm.ROLE_OF["0"]["rightLittleDistal"] == "RightHandPinky3"
