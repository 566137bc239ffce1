"""Hostile VRM files and paths that block (issue 44, items 8 and 9), on the real VRM 0.x robot of
../shared/rigs imported with Blender's glTF importer: a humanoid map giving one bone two roles is refused
as a bone-map file's is; JSON nested 1,000 deep, `skins: 5` and a 32 MB JSON chunk are refused with one
line; the panel never reads a VRM file in draw() and keeps Generate and Export; a VRM File or Bone Map
path naming a FIFO or /dev/stdin is refused at once, never read."""
import json
import os
import signal
import struct
import sys
import time

import bpy
import pytest

import addon_helpers as helpers
import real_rigs
from rlanimate_addon.blender import panel
from rlanimate_addon.core import vrm
from test_registration import RecordingLayout


def _two_roles(gltf):
    """The robot's map with leftLowerArm on leftUpperArm's node: one bone in two roles."""
    bones = gltf["extensions"]["VRM"]["humanoid"]["humanBones"]
    upper = next(entry["node"] for entry in bones if entry["bone"] == "leftUpperArm")
    for entry in bones:
        if entry["bone"] == "leftLowerArm":
            entry["node"] = upper
    return gltf


def _with_text(source, target, text):
    """A copy of the binary glTF `source` whose JSON chunk is `text` (bytes), its BIN chunk kept."""
    data = source.read_bytes()
    rest = data[20 + struct.unpack("<I", data[12:16])[0]:]
    text += b" " * (-len(text) % 4)
    target.write_bytes(b"glTF" + struct.pack("<II", 2, 20 + len(text) + len(rest))
                       + struct.pack("<I4s", len(text), b"JSON") + text + rest)
    return target


def _hostile(kind, folder):
    """The robot VRM made hostile: ('two_roles', 'nested', 'skins', 'huge'); returns its path."""
    source = real_rigs.require("vrm0_robot")
    if kind == "two_roles":
        return real_rigs.rewrite_json(source, folder / "two_roles.vrm", _two_roles)
    text = json.dumps(vrm.read_gltf_json(str(source)))
    if kind == "nested":
        text = text[:-1] + ', "extras": ' + "[" * 1000 + "]" * 1000 + "}"
    elif kind == "skins":
        text = text[:-1] + ', "skins": 5}'
    else:  # a 32 MB chunk: the real JSON padded with spaces
        text += " " * (32 * 2 ** 20)
    return _with_text(source, folder / f"{kind}.vrm", text.encode())


_REFUSALS = {"two_roles": "gives the bone 'upper_arm.L' to the roles LeftArm, LeftForeArm: each role needs a bone",
             "nested": "nests 1,001 deep, more than a glTF's (64 at most)",
             "skins": "its skins is a number, not a list",
             "huge": "bytes, more than a VRM's (2,097,152 at most)"}


def _draw():
    layout = RecordingLayout()
    panel.VIEW3D_PT_rlanimate.draw(type("PanelStandIn", (), {"layout": layout})(), bpy.context)
    return layout.calls


@pytest.mark.parametrize("kind", sorted(_REFUSALS))
def test_a_hostile_vrm_file_is_refused_in_one_line_and_never_read_by_the_panel(settings, tmp_path, monkeypatch, kind):
    rig = real_rigs.load_shared("vrm0_robot", tmp_path)
    hostile = _hostile(kind, tmp_path)
    reads = []
    file_map = vrm.file_map
    monkeypatch.setattr(vrm, "file_map", lambda path: reads.append(path) or file_map(path))
    rig.rlanimate.vrm_file = str(hostile)
    for _ in range(3):  # redraws: never a read, Export and Generate stay
        operators = [call[1] for call in _draw() if call[0] == "operator"]
        assert {"rlanimate.generate_gesture", "rlanimate.export_fbx", "rlanimate.bone_map_from_vrm"} <= set(operators)
    assert reads == [], "draw() read the VRM file"
    start = time.perf_counter()
    with pytest.raises(RuntimeError) as refused:
        helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT")
    assert time.perf_counter() - start < 2.0
    message = str(refused.value).strip().splitlines()
    assert len(message) == 1 and _REFUSALS[kind] in message[0] and str(hostile) in message[0], message
    assert "Traceback" not in str(refused.value)
    assert rig.animation_data is None or rig.animation_data.action is None, "nothing was written"
    assert len(reads) == 1
    with pytest.raises(RuntimeError, match="Error: "):
        helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT")
    assert len(reads) == 1, "the refusal is remembered per file version: a second Generate reads nothing"
    with pytest.raises(RuntimeError, match=_REFUSALS[kind].replace("(", r"\(").replace(")", r"\)")):
        bpy.ops.rlanimate.bone_map_from_vrm(filepath=str(hostile))


def test_the_panel_knows_an_imported_vrms_map_without_reading_it_in_draw(settings, tmp_path, monkeypatch):
    """The import reads the map (the importer's hook), so the panel names the constraints that would override
    the gesture on a VRM rig's arm from its first redraw."""
    rig = real_rigs.load_shared("vrm0_robot", tmp_path)
    monkeypatch.setattr(vrm, "file_map", lambda path: pytest.fail("draw() read the VRM file"))
    rig.pose.bones["lower_arm.R"].constraints.new("COPY_ROTATION").target = helpers.add_empty("Other", (0, 0, 0))
    labels = " ".join(call[1].get("text", "") for call in _draw() if call[0] == "label")
    assert "on lower_arm.R would override the gesture" in labels


def _returns_within(call, seconds=10.0):
    """call()'s result, asserting it came back within `seconds` (a read of a FIFO never does): a SIGALRM
    interrupts it (bpy runs on the main thread only)."""
    def interrupt(signum, frame):
        raise TimeoutError(f"blocked for {seconds} s")
    previous = signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        return call()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@pytest.mark.skipif(sys.platform == "win32", reason="FIFOs and /dev/stdin are POSIX")
@pytest.mark.parametrize("field", ["vrm_file", "bone_map_file"])
@pytest.mark.parametrize("path", ["fifo", "/dev/stdin"])
def test_a_path_that_would_block_is_refused_at_once(settings, tmp_path, field, path):
    if path == "fifo":
        path = str(tmp_path / "pipe")
        os.mkfifo(path)
    elif os.path.isfile(path):
        pytest.skip("stdin is redirected from a regular file")
    rig = helpers.load_sample_rig()
    if field == "vrm_file":
        rig.rlanimate.vrm_file = path
    else:
        settings.bone_map_file = path
    calls = _returns_within(_draw)
    assert "rlanimate.export_fbx" in [call[1] for call in calls if call[0] == "operator"]

    def generate():
        try:
            helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT")
        except RuntimeError as error:
            return str(error)
        return "generated"
    message = _returns_within(generate)
    assert "not a regular file" in message and path in message, message
    assert rig.animation_data is None or rig.animation_data.action is None
