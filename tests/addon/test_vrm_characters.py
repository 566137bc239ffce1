"""VRM characters from their own humanoid map, on a real VRM 0.x file (../shared/rigs) imported with
Blender's glTF importer, on a VRM 1.0 file made from it by rewriting its JSON chunk, and from the VRM
add-on's data on the armature: accepted with no bone-map file, pointing and waving as measured on the
bones the mesh deforms with."""
import math

import bpy
import numpy as np
import pytest

import addon_helpers as helpers
import real_rigs
from rlanimate_addon.blender import armature_io
from rlanimate_addon.core import vrm

EXACT_MEDIAN, EXACT_WORST, OWN_MEDIAN, OWN_WORST = 1.0, 3.0, 5.0, 12.0


@pytest.fixture
def vrm1_file(tmp_path):
    real_rigs.require("vrm0_robot")
    return real_rigs.vrm1_file(tmp_path)


def _check_gestures(rig, settings, family):
    own, _ = real_rigs.point_misses(rig, settings, 4, False, 5)
    start = real_rigs.arm_drop(rig, settings, "RIGHT", 1)  # the first gesture, baked on the still rig
    exact, travel = real_rigs.point_misses(rig, settings, 4, True, 5)
    result, strokes, wave_travel = real_rigs.wave(rig, settings, "RIGHT", 1001)
    print(f"{family}: exact {np.round(exact, 2)}, own {np.round(own, 1)} deg, travel {np.round(travel, 2)} arm "
          f"lengths, wave {strokes} strokes / {wave_travel:.2f}, start arm drop {start:.0f} deg")
    assert real_rigs.measured_bones_deform(rig, settings, "RIGHT") and real_rigs.measured_bones_deform(
        rig, settings, "LEFT"
    )
    assert np.median(exact) <= EXACT_MEDIAN and exact.max() <= EXACT_WORST
    assert np.median(own) <= OWN_MEDIAN and own.max() <= OWN_WORST
    assert result == {"FINISHED"} and strokes >= 4 and min(travel.min(), wave_travel) >= 0.5
    assert 60.0 < start < 85.0, "a T-pose rig with no animation starts in the standing pose, not its T-pose"
    assert armature_io.rig_roles_of(rig)[0] == family


def test_a_vrm0_file_imported_with_the_gltf_importer_points_and_waves(settings, tmp_path):
    rig = real_rigs.load_shared("vrm0_robot", tmp_path)
    assert rig.rlanimate.vrm_file == str(tmp_path / "x.glb"), "the import keeps the VRM file's path"
    roles = real_rigs.roles(rig, settings)
    assert roles["RightArm"] == "upper_arm.R" and roles["RightHandIndex1"] == "index.proximal.R"
    _check_gestures(rig, settings, vrm.FAMILY)


def _arms_off_rest(gltf):
    """The robot with its arm nodes turned 0.6, 0.75 and 0.9 degrees (upper arm, forearm, hand) off their bind
    pose, as an exporter's rounding leaves a VRM 0.x: Blender's glTF importer rests the bones at the bind pose
    and poses them by the nodes."""
    axis = np.array([0.3, 0.2, 0.93]) / np.linalg.norm([0.3, 0.2, 0.93])
    for node in gltf["nodes"]:
        part = node.get("name", "").split(".")[0]
        if part in _ROUNDED:
            half = math.radians(_ROUNDED[part]) / 2
            node["rotation"] = [*(math.sin(half) * axis), math.cos(half)]
    return gltf


_ROUNDED = {"upper_arm": 0.6, "lower_arm": 0.75, "hand": 0.9}


def _degrees_off_rest(pose_bone):
    return math.degrees(2 * math.asin(min(1.0, np.linalg.norm(pose_bone.matrix_basis.to_quaternion()[1:]))))


def test_a_vrm0_whose_arms_sit_a_rounding_off_rest_gestures_from_the_standing_pose(settings, tmp_path):
    """Arms 0.6-0.9 degrees off rest are at rest (gesture.AT_REST, 3 degrees): a gesture starts and ends in the
    standing pose, not in the T-pose. A pose an animator set, 10 degrees, is a pose: the gesture starts from it."""
    source = real_rigs.require("vrm0_robot")
    rig = real_rigs.import_gltf(real_rigs.rewrite_json(source, tmp_path / "rounded.vrm", _arms_off_rest), tmp_path)
    off = {name: _degrees_off_rest(rig.pose.bones[f"{name}.R"]) for name in _ROUNDED}
    assert off == pytest.approx(_ROUNDED, abs=0.01), off
    turn = math.radians(5.0)  # the animator turns the left upper arm 10 degrees
    posed = (math.cos(turn), 0.0, 0.0, math.sin(turn))
    rig.pose.bones["upper_arm.L"].rotation_quaternion = posed
    result, strokes, _ = real_rigs.wave(rig, settings, "RIGHT", 1)
    assert result == {"FINISHED"} and strokes >= 4
    for frame in (1, 150):  # the first and last frames: the standing pose (was: 0.6 degrees, the T-pose)
        assert 60.0 < real_rigs.arm_drop(rig, settings, "RIGHT", frame) < 85.0
        assert tuple(rig.pose.bones["upper_arm.L"].rotation_quaternion) == pytest.approx(posed, abs=1e-5)


def test_a_vrm1_file_maps_bones_only_its_map_can_name(settings, tmp_path, vrm1_file):
    rig = real_rigs.import_gltf(vrm1_file, tmp_path)
    assert rig.rlanimate.vrm_file == str(tmp_path / "x.glb"), "the import keeps the VRM file's path"
    roles = real_rigs.roles(rig, settings)
    gltf = vrm.read_gltf_json(str(vrm1_file))
    thumb = gltf["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]["rightThumbMetacarpal"]["node"]
    assert roles["RightHandThumb1"] == f"joint_{thumb:02d}" and len(roles) == 45
    _check_gestures(rig, settings, vrm.FAMILY)


def test_an_armature_imported_without_its_vrm_path_is_mapped_from_the_file_it_is_given(settings, tmp_path, vrm1_file):
    rig = real_rigs.import_gltf(vrm1_file, tmp_path)
    rig.rlanimate.vrm_file = ""  # imported before the add-on was enabled: nothing but bone names
    target = helpers.add_empty("Target", (1.0, 3.0, 1.5))
    first = r"has no bone for the roles [^.]*\)\. For a VRM character, click 'Bone Map from VRM File'"  # VRM fix first
    with pytest.raises(RuntimeError, match=first):
        helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target)
    assert rig.animation_data is None or rig.animation_data.action is None
    assert bpy.ops.rlanimate.bone_map_from_vrm(filepath=str(vrm1_file)) == {"FINISHED"}
    assert rig.rlanimate.vrm_file == str(vrm1_file)
    assert helpers.generate(rig, settings, behaviour="POINT", arm="RIGHT", target=target) == {"FINISHED"}


def test_a_wrong_or_damaged_vrm_file_is_refused_and_the_armature_keeps_its_map(settings, tmp_path, vrm1_file):
    rig = real_rigs.import_gltf(vrm1_file, tmp_path)
    assert bpy.ops.rlanimate.bone_map_from_vrm(filepath=str(vrm1_file)) == {"FINISHED"}
    other = real_rigs.require("vrm0_robot")  # the 0.x file names its bones otherwise
    with pytest.raises(RuntimeError, match="names bones 'Armature' lacks"):
        bpy.ops.rlanimate.bone_map_from_vrm(filepath=str(other))
    broken = tmp_path / "broken.vrm"
    broken.write_bytes(vrm1_file.read_bytes()[:5000])
    with pytest.raises(RuntimeError, match="truncated"):
        bpy.ops.rlanimate.bone_map_from_vrm(filepath=str(broken))
    assert rig.rlanimate.vrm_file == str(vrm1_file)
    rig.rlanimate.vrm_file = str(tmp_path / "moved.vrm")
    with pytest.raises(RuntimeError, match="Cannot read the VRM file.*clear its VRM File field"):
        helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT")


def _group(name, **properties):
    """A PropertyGroup class with the given properties (annotations), as the VRM add-on declares them."""
    return type(name, (bpy.types.PropertyGroup,), {"__annotations__": properties})


def _pointer(group):
    return bpy.props.PointerProperty(type=group)


_Node = _group("_Node", bone_name=bpy.props.StringProperty())
_HumanBone0 = _group("_HumanBone0", bone=bpy.props.StringProperty(), node=_pointer(_Node))
_Humanoid0 = _group("_Humanoid0", human_bones=bpy.props.CollectionProperty(type=_HumanBone0))
_Vrm1HumanBone = _group("_Vrm1HumanBone", node=_pointer(_Node))
#: VRM 1.0: one pointer per human bone, named in snake case (left_upper_arm, left_thumb_metacarpal, ...).
_Vrm1HumanBones = _group("_Vrm1HumanBones", **{vrm.snake_case(name): _pointer(_Vrm1HumanBone)
                                               for name in vrm.ROLE_OF["1"]})
_Vrm1Humanoid = _group("_Vrm1Humanoid", human_bones=_pointer(_Vrm1HumanBones))
_Vrm0, _Vrm1 = (_group(name, humanoid=_pointer(humanoid))
                for name, humanoid in (("_Vrm0", _Humanoid0), ("_Vrm1", _Vrm1Humanoid)))
_Extension = _group("_Extension", vrm0=_pointer(_Vrm0), vrm1=_pointer(_Vrm1))

_ADDON_LAYOUT = (_Node, _HumanBone0, _Humanoid0, _Vrm0, _Vrm1HumanBone, _Vrm1HumanBones, _Vrm1Humanoid, _Vrm1,
                 _Extension)


@pytest.fixture
def vrm_addon_layout(settings):
    """The VRM add-on's data layout on armatures (saturday06/VRM-Addon-for-Blender, editor/vrm0 and vrm1
    property_group.py: Armature.vrm_addon_extension.vrm0.humanoid.human_bones, a list of {bone,
    node.bone_name}; .vrm1.humanoid.human_bones.<snake_case name>.node.bone_name), registered as the
    add-on registers it, without the add-on."""
    for cls in _ADDON_LAYOUT:
        bpy.utils.register_class(cls)
    bpy.types.Armature.vrm_addon_extension = bpy.props.PointerProperty(type=_Extension)
    yield
    del bpy.types.Armature.vrm_addon_extension
    for cls in reversed(_ADDON_LAYOUT):
        bpy.utils.unregister_class(cls)


@pytest.mark.parametrize("major", ["0", "1"])
def test_the_vrm_addons_map_on_the_armature_is_used(settings, tmp_path, vrm_addon_layout, major):
    source = real_rigs.require("vrm0_robot")
    rig = real_rigs.load_shared("vrm0_robot", tmp_path)
    for bone in rig.data.bones:  # names no family, nor the file, knows: only the add-on's map can tell
        bone.name = "b_" + bone.name.replace(".", "_")
    gltf = vrm.read_gltf_json(str(source))
    names = vrm.imported_bone_names(gltf)
    extension = rig.data.vrm_addon_extension
    for entry in gltf["extensions"]["VRM"]["humanoid"]["humanBones"]:
        bone_name = "b_" + names[entry["node"]].replace(".", "_")
        if major == "0":
            human_bone = extension.vrm0.humanoid.human_bones.add()
            human_bone.bone = entry["bone"]
        else:
            vrm1_name = entry["bone"].replace("ThumbProximal", "ThumbMetacarpal").replace(
                "ThumbIntermediate", "ThumbProximal")
            human_bone = getattr(extension.vrm1.humanoid.human_bones, vrm.snake_case(vrm1_name), None)
            if human_bone is None:  # legs: no role
                continue
        human_bone.node.bone_name = bone_name
    roles = real_rigs.roles(rig, settings)
    assert roles["LeftForeArm"] == "b_lower_arm_L" and roles["RightHandIndex3"] == "b_index_distal_R"
    assert roles["RightHandThumb1"] == "b_thumb_proximal_R" and len(roles) == 45
    target = real_rigs.world_target(rig, settings, "RIGHT", np.random.default_rng(3))
    result, miss, _ = real_rigs.point(rig, settings, "RIGHT", target, 1)
    assert result == {"FINISHED"} and miss <= EXACT_WORST


def test_the_vrm_addons_map_giving_one_bone_two_roles_is_refused_as_a_bone_map_file_is(settings, tmp_path,
                                                                                      vrm_addon_layout):
    rig = real_rigs.load_shared("vrm0_robot", tmp_path)
    human_bones = rig.data.vrm_addon_extension.vrm0.humanoid.human_bones
    for vrm_bone, bone in (("hips", "hips"), ("spine", "spine"), ("neck", "neck"), ("head", "head"),
                           ("rightUpperArm", "upper_arm.R"), ("rightLowerArm", "upper_arm.R"), ("rightHand", "hand.R")):
        entry = human_bones.add()
        entry.bone, entry.node.bone_name = vrm_bone, bone
    with pytest.raises(RuntimeError, match=r"The VRM add-on's humanoid map of 'Armature' gives the bone 'upper_arm\.R' "
                                           r"to the roles RightArm, RightForeArm: each role needs a bone of its own"):
        helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT")
    assert rig.animation_data is None or rig.animation_data.action is None
