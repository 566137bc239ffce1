"""Bone-name maps (core.bone_maps): prefixes, the Bandai Namco skeleton, missing-bone reports."""
import pytest

from rlanimate_addon.core import bone_maps, skeleton

BANDAI_JOINTS = ["joint_Root", "Hips", "Spine", "Chest", "Neck", "Head", "Shoulder_L", "UpperArm_L",
                 "LowerArm_L", "Hand_L", "Shoulder_R", "UpperArm_R", "LowerArm_R", "Hand_R", "UpperLeg_L",
                 "LowerLeg_L", "Foot_L", "Toes_L", "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R"]


@pytest.mark.parametrize("prefix", ["", "mixamorig:", "mixamorig1:", "mixamorig12:"])
def test_mixamo_names_map_to_canonical_with_any_prefix(prefix):
    names = [prefix + name for name in skeleton.BONE_NAMES]
    matched = bone_maps.match_bones(names, bone_maps.MIXAMO)
    assert set(matched) == set(skeleton.BONE_NAMES)
    assert matched["LeftForeArm"] == prefix + "LeftForeArm"
    assert bone_maps.missing_bones(names, bone_maps.MIXAMO) == []


def test_mixamo_rig_without_forearms_reports_exactly_those():
    names = ["mixamorig:" + n for n in skeleton.BONE_NAMES if "ForeArm" not in n]
    assert bone_maps.missing_bones(names, bone_maps.MIXAMO) == ["LeftForeArm", "RightForeArm"]


def test_bandai_namco_maps_every_action_joint_but_spine1_and_index_fingers():
    matched = bone_maps.match_bones(BANDAI_JOINTS, bone_maps.BANDAI_NAMCO)
    assert set(skeleton.ACTION_JOINTS) - set(matched) == {"Spine1", "LeftHandIndex1", "RightHandIndex1"}
    assert matched["Spine2"] == "Chest" and matched["RightArm"] == "UpperArm_R"
    assert bone_maps.BANDAI_NAMCO.shared_bend == {"Spine1": "Spine"}
    assert bone_maps.missing_bones(BANDAI_JOINTS, bone_maps.BANDAI_NAMCO) == []


def test_every_mapped_name_is_a_canonical_bone():
    for bone_map in bone_maps.BONE_MAPS:
        assert set(bone_map.to_canonical.values()) <= set(skeleton.BONE_NAMES)
        assert set(bone_map.shared_bend) <= set(skeleton.BONE_NAMES)


def test_best_map_recognises_each_skeleton():
    assert bone_maps.best_bone_map(BANDAI_JOINTS) is bone_maps.BANDAI_NAMCO
    assert bone_maps.best_bone_map(["mixamorig1:" + n for n in skeleton.BONE_NAMES]) is bone_maps.MIXAMO


def test_missing_bandai_bones_are_named_as_the_source_names_them():
    names = [n for n in BANDAI_JOINTS if n not in ("LowerArm_R", "Neck")]
    assert bone_maps.missing_bones(names, bone_maps.BANDAI_NAMCO) == ["Neck", "LowerArm_R"]
