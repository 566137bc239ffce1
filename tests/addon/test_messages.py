"""Messages that point the right way (issue 44, item 15): Save Bone Map on a rig it half-recognises writes
every role it found and marks the others for the user to fill in; a Rigify arm already in FK is not said
to switch from IK."""
import json

import bpy
import pytest

import addon_helpers as helpers
import real_rigs
from rlanimate_addon.blender import bone_map, generate
from rlanimate_addon.core import rig_roles, skeleton


def _ue_with_blender_sides(rig):
    """The sample character renamed as UE names its bones, with Blender's side suffixes ('upperarm.l',
    'hand.l'), its spine bones given names no family knows: a rig detection half-recognises."""
    for bone in rig.data.bones:
        name = skeleton.strip_prefix(bone.name)
        templates = rig_roles._side_templates(rig_roles.UNREAL, name)
        if name in rig_roles.SPINE:
            bone.name = f"torso_{rig_roles.SPINE.index(name)}"
        elif templates:
            bone.name = templates[0][:-2] + {"_l": ".l", "_r": ".r"}.get(templates[0][-2:], templates[0][-2:])
    return rig


def test_save_bone_map_on_a_half_recognised_rig_writes_every_role_found_and_marks_the_rest(settings, tmp_path):
    rig = helpers.activate(_ue_with_blender_sides(helpers.load_sample_rig()))
    assert "upperarm.l" in rig.data.bones and "hand.r" in rig.data.bones
    with pytest.raises(RuntimeError, match=r"has no bone for the roles Spine \(closest bone naming: Unreal"):
        helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT")
    path = tmp_path / "map.json"
    assert bpy.ops.rlanimate.save_bone_map(filepath=str(path)) == {"FINISHED"}
    summary = bone_map.save_bone_map(bpy.context, str(path))  # the operator's report
    saved = json.loads(path.read_text())["bones"]
    assert list(saved) == list(rig_roles.ROLES), "every role is written, in order"
    assert (saved["LeftArm"], saved["LeftHand"], saved["RightHandIndex1"], saved["Head"]) == (
        "upperarm.l", "hand.l", "index_01.r", "head")
    unknown = [role for role in rig_roles.ROLES if role in rig_roles.SPINE  # renamed, or no UE name for it (eyes, ...4)
               or not rig_roles._side_templates(rig_roles.UNREAL, role)]
    assert [role for role, bone in saved.items() if not bone] == unknown and len(unknown) == 15
    assert 'written as "" to fill in, of which a gesture needs Spine' in summary
    filled = json.loads(path.read_text())
    filled["bones"]["Spine1"] = "torso_1"  # the user types one name and picks the file
    path.write_text(json.dumps(filled))
    settings.bone_map_file = str(path)
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="LEFT") == {"FINISHED"}


@pytest.mark.parametrize("keyed", [1.0, 0.0], ids=["fk", "ik"])
def test_a_rigify_arm_is_said_to_switch_from_ik_only_when_it_was_in_ik(settings, keyed):
    rig = real_rigs.rigify_rig("FK")
    switch = rig.pose.bones["upper_arm_parent.R"]
    switch["IK_FK"] = keyed
    switch.keyframe_insert('["IK_FK"]', frame=1)  # an animated switch: at FK, or at IK
    for key, value in dict(behaviour="WAVE", arm="RIGHT", start_frame=20, frame_count=60).items():
        setattr(settings, key, value)
    summary = generate.generate(bpy.context, settings)
    assert summary.startswith("Baked Wave Right")
    assert ("switched from IK to FK" in summary) == (keyed == 0.0), summary
