"""The panel's behaviours are the selected agent's: the Behaviour enum lists them (POINT and WAVE keep their
ids), a stored choice survives a change of agent, the panel shows Target or Exaggeration by the behaviour's
kind, and Generate bakes a behaviour the agent declares beyond the shipped agent's (tests/addon/declared_agents.py
widens the shipped agent by two behaviours with numpy alone, so this runs on Blender 4.2 and 5.0)."""
import bpy
import numpy as np
import pytest

import addon_helpers
import declared_agents
from rlanimate_addon.blender import action_adapter, gestures, preferences, properties
from test_registration import RecordingLayout, _draw

ADDED = [("BECKON", "target"), ("SHRUG", "intensity")]


@pytest.fixture
def widened_settings(settings, tmp_path):
    """Scene.rlanimate with an agent file of the shipped behaviours and ADDED written (not yet selected);
    returns its path and its behaviours."""
    path = tmp_path / "widened.npz"
    return settings, path, declared_agents.widened_agent(path, ADDED).names


def _listed(settings):
    return [item[0] for item in properties.behaviour_items(settings, bpy.context)]


def _shown(settings):
    return {call[2] for call in _draw(settings) if call[0] == "prop"}


def test_the_enum_lists_the_selected_agents_behaviours_and_a_stored_choice_survives_a_change_of_agent(
        widened_settings, capfd):
    """Switching to an agent that lacks the chosen behaviour keeps the choice, shows it as not in this agent (so
    Blender reads it without a 'matches no enum' warning), and the panel and Generate name it."""
    settings, path, widened = widened_settings
    shipped = declared_agents.shipped_behaviours()
    preferences = addon_helpers.addon_preferences()
    assert _listed(settings) == list(shipped) and settings.behaviour == "POINT"
    preferences.agent_path = str(path)
    assert _listed(settings) == list(widened) and {"BECKON", "SHRUG"} < set(widened)
    settings.behaviour = "BECKON"
    assert settings.behaviour == "BECKON"
    preferences.agent_path = ""  # the bundled agent has no Beckon: the choice is kept, not replaced
    assert _listed(settings) == [*shipped, "BECKON"]
    assert properties.behaviour_items(settings, bpy.context)[-1][1] == "Beckon (not in this agent)"
    assert properties.chosen_behaviour(settings, bpy.context) == "BECKON" and settings.behaviour == "BECKON"
    errors = " ".join(c[1].get("text", "") for c in _draw(settings) if c[0] == "label" and c[1].get("icon") == "ERROR")
    assert f"This agent does not perform Beckon (it performs {declared_agents.listed_titles(shipped)})" in errors
    with pytest.raises(RuntimeError, match=f"The selected agent performs {declared_agents.listed_titles(shipped)}, "
                                           "no Beckon: pick one of its behaviours"):
        addon_helpers.generate(addon_helpers.load_sample_rig(), settings)
    assert "matches no enum" not in "".join(capfd.readouterr())
    preferences.agent_path = str(path)
    assert settings.behaviour == "BECKON" and _listed(settings) == list(widened), "the agent that has it again"
    settings.behaviour = "WAVE"
    preferences.agent_path = ""
    assert settings.behaviour == "WAVE" and _listed(settings) == list(shipped), "Point and Wave keep their values"


def test_a_choice_stored_before_its_name_was_kept_is_read_quietly_as_none_of_the_agents(widened_settings, capfd):
    settings, path, _ = widened_settings
    settings["behaviour"] = properties.behaviour_number("BECKON")  # no behaviour_name: a file saved before it
    assert properties.chosen_behaviour(settings, bpy.context) == ""
    errors = " ".join(c[1].get("text", "") for c in _draw(settings) if c[0] == "label" and c[1].get("icon") == "ERROR")
    assert "The chosen behaviour is not one of this agent's" in errors
    assert "matches no enum" not in "".join(capfd.readouterr()), "the panel reads the raw number, never the enum"


def test_preferences_name_the_chosen_agents_behaviours(widened_settings):
    settings, path, widened = widened_settings

    def labels():
        layout = RecordingLayout()
        preferences.RLANIMATE_AP_preferences.draw(type("PreferencesStandIn", (), {"layout": layout})(), bpy.context)
        return [call[1].get("text", "") for call in layout.calls if call[0] == "label"]

    assert f"Behaviours: {declared_agents.listed_titles(declared_agents.shipped_behaviours())}" in labels()
    addon_helpers.addon_preferences().agent_path = str(path)
    assert f"Behaviours: {declared_agents.listed_titles(widened)}" in labels()
    assert "Beckon" in declared_agents.listed_titles(widened)


def test_the_panel_shows_target_for_a_target_behaviour_and_exaggeration_for_an_intensity_one(widened_settings):
    settings, path, _ = widened_settings
    addon_helpers.addon_preferences().agent_path = str(path)
    settings.behaviour = "BECKON"
    shown = _shown(settings)
    assert "target" in shown and "exaggeration" not in shown
    assert "exact_aim" not in shown, "Exact Aim lays the index finger on the target: Point's alone"
    settings.behaviour = "SHRUG"
    shown = _shown(settings)
    assert "exaggeration" in shown and "target" not in shown


def test_generate_bakes_the_agents_own_behaviours_and_follows_a_target_behaviours_target(widened_settings):
    settings, path, _ = widened_settings
    addon_helpers.addon_preferences().agent_path = str(path)
    rig = addon_helpers.load_sample_rig()
    with pytest.raises(RuntimeError, match="Beckon needs a target"):
        addon_helpers.generate(rig, settings, behaviour="BECKON", arm="RIGHT")
    target = addon_helpers.add_empty("Target", (-1.5, -2.0, 1.6))
    frames = np.arange(1, 91)
    assert addon_helpers.generate(rig, settings, behaviour="BECKON", arm="RIGHT", target=target, start_frame=1,
                                  frame_count=90) == {"FINISHED"}
    beckon = gestures.last_targeted(rig)
    assert beckon is not None and beckon.record["kind"] == "target" and beckon.record["behaviour"] == "BECKON"
    assert beckon.action.name.startswith("RLAnimate Beckon Right")
    aimed = np.reshape(beckon.record["aimed_at"], (-1, 3))
    assert len(aimed) == len(frames) and np.allclose(aimed, aimed[0])
    hand = addon_helpers.rig_bone(rig, "RightHand")
    travel = np.linalg.norm(addon_helpers.bone_heads(rig, [hand], frames)[:, 0] - addon_helpers.bone_heads(
        rig, [hand], frames[:1])[0, 0], axis=1).max()
    assert travel > 0.1, f"the hand moves ({travel:.3f} m)"
    assert addon_helpers.generate(rig, settings, behaviour="SHRUG", arm="LEFT", exaggeration=0.9,
                                  start_frame=200, frame_count=80) == {"FINISHED"}
    raised = gestures.placed_gestures(rig)[-1]  # the topmost
    assert (raised.record["behaviour"], raised.record["kind"]) == ("SHRUG", "intensity")
    assert gestures.last_targeted(rig).action == beckon.action, "Follow Target follows the target behaviour"


def _arm_and_hand_keys(rig, arm="Right"):
    """({bone: keyed values} of the upper arm's rotation, whether the pointing hand's fingers are keyed) of the
    armature's topmost gesture."""
    curves = action_adapter.all_fcurves(gestures.placed_gestures(rig)[-1].action)
    upper = addon_helpers.rig_bone(rig, f"{arm}Arm")
    values = np.array([[p.co[1] for p in c.keyframe_points] for c in curves if f'"{upper}"' in c.data_path])
    middle = addon_helpers.rig_bone(rig, f"{arm}HandMiddle1")
    return values, any(f'"{middle}"' in c.data_path for c in curves)


def test_a_taught_behaviour_declared_to_point_gets_exact_aim_and_the_pointing_hand(settings, tmp_path):
    """What Point gets comes from what a behaviour does: AIM_AT, declared "does": "point", shows Exact Aim, keys
    the pointing hand, and Exact Aim turns its arm; BECKON, declaring nothing, gets neither."""
    path = tmp_path / "aim_at.npz"
    declared_agents.widened_agent(path, [("AIM_AT", "target", "point"), ("BECKON", "target")])
    addon_helpers.addon_preferences().agent_path = str(path)
    rig = addon_helpers.load_sample_rig()
    target = addon_helpers.add_empty("Target", (-1.5, -2.0, 1.6))
    for behaviour, points in (("AIM_AT", True), ("BECKON", False)):
        settings.behaviour = behaviour
        assert ("exact_aim" in _shown(settings)) == points
        keys = {}
        for exact in (True, False):  # made, then made again in place with Exact Aim off
            assert addon_helpers.generate(rig, settings, behaviour=behaviour, arm="RIGHT", target=target,
                                          exact_aim=exact, start_frame=1, frame_count=90) == {"FINISHED"}
            keys[exact], hand = _arm_and_hand_keys(rig)
            assert hand == points, f"{behaviour}: the pointing hand only for a behaviour that points"
        assert np.allclose(keys[True], keys[False]) != points, f"{behaviour}: Exact Aim turns a pointing arm alone"
        assert len(gestures.placed_gestures(rig)) == 1, "each bake made the selected gesture again in place"
