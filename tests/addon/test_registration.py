"""Registration, the Scene.rlanimate contract, and the N-panel's placement and draw()."""
import os
import time
import types
import zipfile
from unittest import mock

import bpy
import numpy as np
import pytest

import addon_helpers
import rlanimate_addon
from rlanimate_addon.blender import panel, registration
from rlanimate_addon.blender import properties as blender_properties
from rlanimate_addon.core import runtime

CONTRACT = {
    "behaviour": ("ENUM", {"POINT", "WAVE"}),
    "arm": ("ENUM", {"LEFT", "RIGHT"}),
    "target": ("POINTER", None),
    "exaggeration": ("FLOAT", None),
    "tempo": ("FLOAT", None),
    "frame_count": ("INT", None),
    "start_frame": ("INT", None),
    "seed": ("INT", None),
    "exact_aim": ("BOOLEAN", None),
}


def _registered():
    return (hasattr(bpy.types.Scene, "rlanimate"), hasattr(bpy.types, "VIEW3D_PT_rlanimate"),
            hasattr(bpy.ops.rlanimate, "generate_gesture") and "generate_gesture" in dir(bpy.ops.rlanimate))


def test_register_and_unregister_twice():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    for _ in range(2):
        rlanimate_addon.register()
        assert _registered() == (True, True, True)
        for cls in registration.CLASSES:
            assert cls.is_registered
        rlanimate_addon.unregister()
        assert not hasattr(bpy.types.Scene, "rlanimate") and not hasattr(bpy.types.Object, "rlanimate")
        assert not any(cls.is_registered for cls in registration.CLASSES)


def test_scene_settings_keep_the_contract(settings):
    properties = settings.bl_rna.properties
    for name, (kind, items) in CONTRACT.items():
        assert properties[name].type == kind, name
        if items is not None:  # `behaviour` lists the selected agent's (the bundled one's) behaviours
            listed = (properties[name].enum_items if name != "behaviour"
                      else [types.SimpleNamespace(identifier=item[0]) for item in
                            blender_properties.behaviour_items(settings, bpy.context)])
            identifiers = {item.identifier for item in listed}
            assert identifiers == items if name != "behaviour" else items <= identifiers, (name, identifiers)
            for value in items:
                setattr(settings, name, value)
                assert getattr(settings, name) == value
    assert properties["target"].fixed_type.identifier == "Object"
    assert (properties["exaggeration"].hard_min, properties["exaggeration"].hard_max) == (0.0, 1.0)
    assert settings.tempo == 0.0 and properties["tempo"].hard_min == 0.0, "by default the agent chooses the tempo"
    assert settings.frame_count >= 2, "the default length must be a usable gesture"
    assert settings.exact_aim is True, "aim correction is on by default"
    assert {"REGISTER", "UNDO"} <= set(bpy.types.RLANIMATE_OT_generate_gesture.bl_options)
    export = bpy.ops.rlanimate.export_fbx.get_rna_type()
    assert "filepath" in export.properties


def test_panel_sits_in_the_3d_view_sidebar_under_rlanimate(settings):
    cls = bpy.types.VIEW3D_PT_rlanimate
    assert (cls.bl_space_type, cls.bl_region_type, cls.bl_category) == ("VIEW_3D", "UI", "RLAnimate")


class RecordingLayout:
    """Stands in for bpy.types.UILayout: records prop(), operator() and label() calls from draw()."""

    def __init__(self, calls=None):
        self.calls = [] if calls is None else calls

    def _nested(self, *args, **kwargs):
        return RecordingLayout(self.calls)

    row = column = box = split = column_flow = grid_flow = _nested

    def prop(self, data, name, **kwargs):
        self.calls.append(("prop", data, name, kwargs))

    def prop_search(self, data, name, search_data, search_name, **kwargs):
        self.calls.append(("prop_search", data, name, search_data, search_name, kwargs))

    def operator(self, idname, **kwargs):
        self.calls.append(("operator", idname, kwargs))
        return kwargs.setdefault("properties", types.SimpleNamespace())

    def label(self, **kwargs):
        self.calls.append(("label", kwargs))

    def separator(self, **kwargs):
        pass


def _draw(settings):
    layout = RecordingLayout()
    stand_in = type("PanelStandIn", (), {"layout": layout})()
    panel.VIEW3D_PT_rlanimate.draw(stand_in, bpy.context)
    return layout.calls


_ICONS = bpy.types.UILayout.bl_rna.functions["prop"].parameters["icon"].enum_items.keys()


@pytest.mark.parametrize("behaviour", ["POINT", "WAVE"])
def test_panel_draw_uses_only_existing_properties_operators_and_icons(settings, behaviour):
    settings.behaviour = behaviour
    calls = _draw(settings)
    shown = set()
    for call in calls:
        if call[0] == "prop":
            _, data, name, kwargs = call
            assert name in data.bl_rna.properties, f"draw() shows a missing property {name!r}"
            shown.add(name)
        elif call[0] == "operator":
            group, op = call[1].split(".")
            assert op in dir(getattr(bpy.ops, group)), f"draw() shows a missing operator {call[1]!r}"
        kwargs = call[-1]
        assert kwargs.get("icon", "NONE") in _ICONS
    assert {"behaviour", "arm", "frame_count", "start_frame", "seed"} <= shown
    assert ("exaggeration" in shown) == (behaviour == "WAVE")
    assert ("tempo" in shown) == (behaviour == "WAVE")
    assert ("target" in shown) == (behaviour == "POINT")
    assert ("exact_aim" in shown) == (behaviour == "POINT")
    operators = [c[1] for c in calls if c[0] == "operator"]
    assert operators == ["rlanimate.save_bone_map", "rlanimate.generate_gesture", "rlanimate.export_fbx"]
    labels = " ".join(c[1].get("text", "") for c in calls if c[0] == "label")
    assert "supported" in labels, "the panel must show the supported length range"


def test_panel_offers_the_bones_of_an_armature_target(settings):
    settings.behaviour = "POINT"
    settings.target = addon_helpers.build_rig("Other")
    searches = [c for c in _draw(settings) if c[0] == "prop_search"]
    assert len(searches) == 1
    _, data, name, search_data, search_name, _ = searches[0]
    assert name in data.bl_rna.properties and search_name in search_data.bl_rna.properties
    assert (name, search_data, search_name) == ("target_bone", settings.target.data, "bones")
    settings.target = addon_helpers.add_empty("Empty", (0.0, -2.0, 1.0))
    assert not [c for c in _draw(settings) if c[0] == "prop_search"], "an object target has no bones to pick"


def test_panel_names_a_damaged_agent_file_instead_of_failing(settings, tmp_path):
    damaged = tmp_path / "broken.npz"
    damaged.write_bytes(b"not an agent")
    addon_helpers.addon_preferences().agent_path = str(damaged)
    labels = [c[1] for c in _draw(settings) if c[0] == "label"]
    assert any(label.get("icon") == "ERROR" for label in labels)
    assert any("broken.npz" in label.get("text", "") for label in labels)


def test_panel_draws_in_under_a_millisecond_after_one_failed_load(settings, tmp_path):
    """A bad agent file is read once: the failure is cached per path and modification time."""
    bomb = tmp_path / "bomb.npz"
    with zipfile.ZipFile(bomb, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("__metadata__.npy", bytes(64 * 2 ** 20))  # 64 MB of zeros, 64 KB deflated
    addon_helpers.addon_preferences().agent_path = str(bomb)
    with mock.patch.object(runtime, "load_agent", wraps=runtime.load_agent) as load:
        labels = [c[1] for c in _draw(settings) if c[0] == "label"]
        times = []
        for _ in range(50):
            start = time.perf_counter()
            _draw(settings)
            times.append(time.perf_counter() - start)
    assert load.call_count == 1, "the failed load is cached"
    assert any("bomb.npz" in label.get("text", "") for label in labels)
    assert np.median(times) < 1e-3, f"panel draw took {np.median(times) * 1e3:.2f} ms"
    os.utime(bomb, ns=(0, 0))  # another version of the file is read again
    with mock.patch.object(runtime, "load_agent", wraps=runtime.load_agent) as load:
        _draw(settings)
    assert load.call_count == 1


def test_panel_offers_to_mute_constraints_that_override_the_gesture(settings):
    rig = addon_helpers.load_sample_rig()
    forearm = rig.pose.bones[addon_helpers.rig_bone(rig, "LeftForeArm")]
    forearm.constraints.new("COPY_ROTATION").target = addon_helpers.add_empty("Other", (0, 0, 0))
    calls = _draw(settings)
    labels = " ".join(c[1].get("text", "") for c in calls if c[0] == "label")
    assert f"'Copy Rotation' (Copy Rotation, target Other) on {forearm.name} would override the gesture" in labels
    mute = [c for c in calls if c[0] == "operator" and c[2].get("text") == "Generate, Muting Constraints"]
    assert len(mute) == 1 and mute[0][1] == "rlanimate.generate_gesture"
    assert mute[0][2]["properties"].mute_constraints is True
    times = []
    for _ in range(50):  # the rig's bone roles are detected once, not on every redraw
        start = time.perf_counter()
        _draw(settings)
        times.append(time.perf_counter() - start)
    assert np.median(times) < 1e-3, f"panel draw took {np.median(times) * 1e3:.2f} ms with an armature active"
