"""Bone roles: Mixamo names with any prefix, the other rig families, required roles, bone-map files."""
import json

import pytest

from rlanimate_addon.core import rig_roles, skeleton
from rlanimate_addon.core.errors import RLAnimateError

MIXAMO = list(skeleton.BONE_NAMES)


@pytest.mark.parametrize("rename", [
    lambda n: "mixamorig:" + n, lambda n: "mixamorig1:" + n, lambda n: "mixamorig_" + n,
    lambda n: "mixamorig" + n, lambda n: ("MIXAMORIG:" + n).upper(), lambda n: "Armature|" + n.lower(),
])
def test_mixamo_names_match_with_any_prefix_in_any_case(rename):
    family, roles = rig_roles.detect([rename(n) for n in MIXAMO])
    assert family is rig_roles.MIXAMO
    assert roles["LeftArm"] == rename("LeftArm") and roles["RightHandIndex4"] == rename("RightHandIndex4")
    assert len(roles) == len(rig_roles.ROLES)


def _family_names(family):
    """Every bone name the family's first templates give, both sides."""
    return [rig_roles._side_templates(family, role)[0] for role in rig_roles.ROLES
            if rig_roles._side_templates(family, role)]


@pytest.mark.parametrize("family", rig_roles.FAMILIES, ids=lambda f: f.name)
def test_each_family_is_detected_from_its_own_names_with_every_gesture_role(family):
    names = _family_names(family) + ["DEF-upper_arm.L", "ORG-spine", "MCH-forearm_ik.L", "root", "ik_hand_gun"]
    detected, roles = rig_roles.detect(names)
    assert detected is family
    for arm in skeleton.ARMS:
        rig_roles.check_roles("Rig", roles, arm, family.name)
    if family is not rig_roles.RIGIFY_DEFORM:
        assert not any(bone.startswith(("DEF-", "ORG-", "MCH-")) for bone in roles.values())


def test_a_rigify_game_export_keys_its_deform_bones_and_a_whole_rigify_rig_its_controls():
    deform = _family_names(rig_roles.RIGIFY_DEFORM) + ["DEF-upper_arm.L.001", "DEF-forearm.R.001", "root"]
    family, roles = rig_roles.detect(deform)
    assert (
        family is rig_roles.RIGIFY_DEFORM and roles["LeftArm"] == "DEF-upper_arm.L" and roles["Head"] == "DEF-spine.006"
    )
    family, roles = rig_roles.detect(deform + _family_names(rig_roles.RIGIFY))
    assert family is rig_roles.RIGIFY and roles["LeftArm"] == "upper_arm_fk.L"


@pytest.mark.parametrize("prefix", ["Bip01 ", "Bip001 "])
def test_biped_and_spaced_mixamo_names_are_detected(prefix):
    names = [prefix + n for n in ("Pelvis", "Spine", "Spine1", "Spine2", "Neck", "Head")] + [
        f"{prefix}{s} {part}" for s in "LR" for part in ("Clavicle", "UpperArm", "Forearm", "Hand", "Finger0",
                                                        "Finger1", "Finger11", "Finger12")]
    family, roles = rig_roles.detect(names)
    assert family is rig_roles.BIPED
    assert (roles["RightArm"], roles["LeftHandIndex3"], roles["LeftHandThumb1"]) == (
        f"{prefix}R UpperArm", f"{prefix}L Finger12", f"{prefix}L Finger0")
    spaced = ["mixamorig:" + n.replace("Left", "Left ").replace("Right", "Right ") for n in MIXAMO]
    family, roles = rig_roles.detect(spaced)
    assert family is rig_roles.MIXAMO and roles["RightForeArm"] == "mixamorig:Right ForeArm"


def test_rigify_keys_the_fk_controls():
    _, roles = rig_roles.detect(_family_names(rig_roles.RIGIFY))
    assert (roles["LeftArm"], roles["RightForeArm"], roles["Spine"]) == (
        "upper_arm_fk.L",
        "forearm_fk.R",
        "spine_fk.002",
    )


def test_unreal_5_spine_keys_its_top_spine_bone():
    names = _family_names(rig_roles.UNREAL) + ["spine_04", "spine_05"]
    assert rig_roles.detect(names)[1]["Spine2"] == "spine_05"


def test_missing_roles_are_listed_with_how_to_map_them():
    names = [n for n in MIXAMO if n not in ("Neck", "RightHand", "Spine", "Spine1", "Spine2")]
    family, roles = rig_roles.detect(names)
    missing = r"roles Spine, Neck, RightHand \(closest bone naming: Mixamo\).*Bone Map"
    with pytest.raises(RLAnimateError, match=missing) as refused:
        rig_roles.check_roles("Hero", roles, "RIGHT", family.name)
    message = str(refused.value)  # the VRM fix first, the bone map next, renaming bones last
    assert message.index("'Bone Map from VRM File'") < message.index("'Save Bone Map'") < message.index("rename")
    rig_roles.check_roles("Hero", {**roles, "Neck": "n", "Spine": "s"}, "LEFT", family.name)  # the left arm is whole


def test_a_saved_bone_map_names_every_role_and_leaves_those_not_found_empty():
    text = rig_roles.bone_map_json("Custom", {"Spine": "a", "Neck": "b", "Head": "c"})
    saved = json.loads(text)
    assert list(saved["bones"]) == list(rig_roles.ROLES) and '""' in saved["note"]
    assert saved["bones"]["Spine"] == "a" and saved["bones"]["LeftArm"] == "" and len(rig_roles.ROLES) == 56
    filled = {**saved, "bones": {**saved["bones"], "LeftArm": "d"}}  # what the user types
    assert rig_roles.read_bone_map(json.dumps(filled), ["a", "b", "c", "d"]) == (
        "Custom", {"Spine": "a", "Neck": "b", "Head": "c", "LeftArm": "d"})


def test_ue_names_with_blender_side_suffixes_are_the_ue_family():
    """'upperarm.l', 'hand.L', 'index_01-l': the UE family's names with another side separator (issue 44:
    Save Bone Map kept 5 roles of a rig so named)."""
    unreal = _family_names(rig_roles.UNREAL)
    names = [name[:-2] + {"_l": ".l", "_r": ".R"}.get(name[-2:], name[-2:]) for name in unreal]
    assert "upperarm.l" in names and "index_01.R" in names
    family, roles = rig_roles.detect(names)
    assert family is rig_roles.UNREAL and len(roles) == len(rig_roles.detect(unreal)[1]) == 44
    assert roles["LeftArm"] == "upperarm.l" and roles["RightHand"] == "hand.R"
    for family in rig_roles.FAMILIES:  # every family still finds its own names first
        assert rig_roles.detect(_family_names(family))[0] is family


def test_a_bone_map_file_round_trips_and_bad_files_are_refused():
    bones = ["a", "b", "c"]
    text = rig_roles.bone_map_json("Custom", {"Spine": "a", "Neck": "b", "Head": "c"})
    assert rig_roles.read_bone_map(text, bones) == ("Custom", {"Spine": "a", "Neck": "b", "Head": "c"})
    with pytest.raises(RLAnimateError, match="not valid"):
        rig_roles.read_bone_map("{", bones)
    with pytest.raises(RLAnimateError, match="unknown roles Elbow"):
        rig_roles.read_bone_map(json.dumps({"bones": {"Elbow": "a"}}), bones)
    with pytest.raises(RLAnimateError, match="lacks: z"):
        rig_roles.read_bone_map(json.dumps({"bones": {"Neck": "z"}}), bones)
    for value in (["a"], None, 3):
        with pytest.raises(RLAnimateError, match="one name \\(a string, \"\" for none\\) per role"):
            rig_roles.read_bone_map(json.dumps({"bones": {"Neck": value}}), bones)
    with pytest.raises(RLAnimateError, match="gives the bone 'a' to the roles Neck, Head"):
        rig_roles.read_bone_map(json.dumps({"bones": {"Spine": "b", "Neck": "a", "Head": "a"}}), bones)
