"""The panel with a bad agent file chosen in the preferences: its draw never raises, Generate, Export and
Save Bone Map stay, and the box names the file and what is wrong with it (issue 29's LZMA, header-length,
entry-count and 1e300 files; issue 44's wave_rhythm and arms of the wrong type)."""
import io
import json
import struct
import time
import zipfile

import bpy
import numpy as np
import pytest

import addon_helpers
from rlanimate_addon.blender import panel, preferences
from test_registration import RecordingLayout


def _lzma(data):
    data = bytearray(data)
    central = data.index(b"PK\x01\x02")
    data[central + 10:central + 12] = struct.pack("<H", zipfile.ZIP_LZMA)  # the audit's 2-byte change
    return bytes(data)


def _rezipped(data, replace):
    buffer = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as source, zipfile.ZipFile(buffer, "w") as archive:
        for info in source.infolist():
            archive.writestr(info.filename, replace(info.filename, source.read(info)))
    return buffer.getvalue()


def _header_bomb(data):
    def replace(name, content):
        if name != "__metadata__.npy":
            return content
        return b"\x93NUMPY\x02\x00" + struct.pack("<I", 0xFFFFFFFF) + b" " * 2 ** 16
    return _rezipped(data, replace)


def _huge(data):
    def replace(name, content):
        if name == "__metadata__.npy":
            return content
        buffer = io.BytesIO()
        np.save(buffer, np.load(io.BytesIO(content)).astype(np.float64) * 1e300)
        return buffer.getvalue()
    return _rezipped(data, replace)


def _entries(data):
    data = bytearray(data)
    data[-14:-10] = struct.pack("<2H", 0xFFFF, 0xFFFF)  # the end record claims 65,535 entries
    return bytes(data)


def _rhythm(change):
    """A maker of the agent with its metadata's wave_rhythm passed through change(wave_rhythm)."""
    def make(data):
        def replace(name, content):
            if name != "__metadata__.npy":
                return content
            metadata = json.loads(str(np.load(io.BytesIO(content))))
            metadata["wave_rhythm"] = change(metadata["wave_rhythm"])
            buffer = io.BytesIO()
            np.save(buffer, np.array(json.dumps(metadata)))
            return buffer.getvalue()
        return _rezipped(data, replace)
    return make


_RHYTHMS = [(_rhythm(lambda r: "fast"), "wave_rhythm is a string"),
            (_rhythm(lambda r: [2.0, 0.1]), "wave_rhythm is a list"),
            (_rhythm(lambda r: 2.5), "wave_rhythm is a number"),
            (_rhythm(lambda r: {**r, "arms": [["LEFT"]] * len(r["examples"])}), "wave_rhythm.arms must be")]


@pytest.mark.parametrize("make, problem", [(_lzma, "zip method 14 (LZMA)"),
                                           (_header_bomb, "claims 4,294,967,295 bytes"),
                                           (_huge, "values as large as"), (_entries, "65,535 entries"),
                                           *_RHYTHMS],
                         ids=["lzma", "header_length", "1e300", "entry_count", "rhythm_string", "rhythm_list",
                              "rhythm_number", "arms_lists"])
def test_a_bad_agent_file_keeps_the_panel_with_generate_and_export(settings, tmp_path, make, problem):
    path = tmp_path / "bad.npz"
    path.write_bytes(make(preferences.BUNDLED_AGENT.read_bytes()))
    addon_helpers.addon_preferences().agent_path = str(path)
    for behaviour in ("POINT", "WAVE"):
        settings.behaviour = behaviour
        layout = RecordingLayout()
        start = time.perf_counter()
        panel.VIEW3D_PT_rlanimate.draw(type("PanelStandIn", (), {"layout": layout})(), bpy.context)
        assert time.perf_counter() - start < 2.0
        operators = [call[1] for call in layout.calls if call[0] == "operator"]
        assert {"rlanimate.generate_gesture", "rlanimate.export_fbx", "rlanimate.save_bone_map"} <= set(operators)
        errors = [call[1]["text"] for call in layout.calls if call[0] == "label" and call[1].get("icon") == "ERROR"]
        assert len(errors) == 1 and str(path) in errors[0] and problem in errors[0], errors
    addon_helpers.addon_preferences().agent_path = ""
