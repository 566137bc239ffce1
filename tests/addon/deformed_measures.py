"""Real rigs made by others (../shared/rigs, see its README), imported as a user imports them, and
gestures measured on the bones their meshes deform with, as Blender plays them.

The finger is measured from joint positions, independently of the add-on's own finger line: from the
index base's head to the head of the last joint of its chain (following the bones below the index
base to the fingertip, an end bone included), all in world space after `frame_set`.
"""
import math
import shutil
from pathlib import Path

import addon_helpers as helpers
import bpy
import numpy as np
import pytest
from test_generate import random_target

from rlanimate_addon.blender import armature_io
from rlanimate_addon.core import behaviour_metrics, gesture

RIGS = helpers.ROOT.parent / "shared" / "rigs"
VRM0 = RIGS / "vrm" / "unavi_robot_vrm0.vrm"
UE_GLB = RIGS / "unreal" / "mesh2motion_human-male.glb"
KENNEY_GLB = RIGS / "mixamo" / "kenney_human_mesh2motion.glb"


def require(path):
    """Skip the test, with a message, when a real rig is absent (a checkout without ../shared)."""
    if not Path(path).is_file():
        pytest.skip(f"real rig {path} is absent: these tests read ../shared/rigs (see its README)")
    return Path(path)


def import_gltf(path, folder):
    """Import a .glb, or a .vrm under a temporary .glb name, with Blender's glTF importer (default options);
    returns the armature, active."""
    path = Path(path)
    if path.suffix.lower() != ".glb":
        copy = Path(folder) / "x.glb"
        shutil.copyfile(path, copy)
        path = copy
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=str(path))
    return helpers.activate(next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE"))


def roles(rig):
    """{role: bone} as Generate finds them (bone-map file, VRM map or detection)."""
    return armature_io.rig_roles_of(rig, bpy.context.scene.rlanimate.bone_map_file)[1]


def deforming_bones(rig):
    """Names of the bones the rig's skinned meshes deform with (vertex groups of deform bones)."""
    groups = {g.name for o in bpy.context.scene.objects if o.type == "MESH"
              and any(m.type == "ARMATURE" and m.object == rig for m in o.modifiers) for g in o.vertex_groups}
    return {b.name for b in rig.data.bones if b.use_deform and b.name in groups}


def index_joints(rig, arm):
    """(index base bone, fingertip-most bone): the chain below the index base, the longest branch."""
    start = rig.data.bones[roles(rig)[gesture.skeleton.ARM_PREFIX[arm] + "HandIndex1"]]
    bone = start
    while bone.children:
        bone = max(bone.children, key=lambda b: len(b.children_recursive))
    return start.name, bone.name


def _world_heads(rig, bones):
    world = np.array(rig.matrix_world, dtype=np.float64)
    return np.array([(world @ np.append(rig.pose.bones[b].head, 1.0))[:3] for b in bones])


def finger_angles(rig, arm, target, frames):
    """(F,) degrees between the finger's joint line and its base-to-target line, and (F, 3) finger bases."""
    base_bone, tip_bone = index_joints(rig, arm)
    angles, bases = [], []
    for frame in frames:
        bpy.context.scene.frame_set(int(frame))
        base, tip = _world_heads(rig, (base_bone, tip_bone))
        finger, to_target = tip - base, np.asarray(target) - base
        cos = finger @ to_target / np.linalg.norm(finger) / np.linalg.norm(to_target)
        angles.append(math.degrees(math.acos(np.clip(cos, -1.0, 1.0))))
        bases.append(base)
    return np.array(angles), np.array(bases)


def shoulder_width(rig):
    found = roles(rig)
    return float(np.linalg.norm(np.subtract(*_rest_world(rig, [found["LeftArm"], found["RightArm"]]))))


def _rest_world(rig, bones):
    world = np.array(rig.matrix_world, dtype=np.float64)
    return [(world @ np.append(rig.data.bones[b].head_local, 1.0))[:3] for b in bones]


def hold_miss(rig, angles, bases):
    """Median finger angle over the pointing hold (behaviour_metrics.hold_frames), else at the apex."""
    render = bpy.context.scene.render
    hold = behaviour_metrics.hold_frames(bases, shoulder_width(rig), render.fps / render.fps_base)
    if hold is None:
        return float(angles[int(np.argmax(np.linalg.norm(bases - bases[0], axis=1)))])
    return float(np.median(angles[hold[0]:hold[1] + 1]))


def world_target(rig, arm, rng):
    """An unseen target placed relative to the rig as random_target places it relative to the canonical
    character: the rig's own facing, size and world transform applied."""
    found = roles(rig)
    heads = {r: np.array(rig.data.bones[b].head_local) for r, b in found.items()}
    frame = gesture.character_frame(heads)
    shoulder = heads[gesture.skeleton.ARM_PREFIX[arm] + "Arm"]
    size = np.linalg.norm(heads["Head"] - shoulder)
    canonical = gesture.canonical_rig().rest_heads
    canonical_size = np.linalg.norm(np.subtract(canonical["Head"], canonical[gesture.skeleton.ARM_PREFIX[arm] + "Arm"]))
    local = frame.T @ (random_target(arm, rng) * size / canonical_size)
    return (np.array(rig.matrix_world, dtype=np.float64) @ np.append(local, 1.0))[:3]


def arm_length(rig, arm):
    found = roles(rig)
    prefix = gesture.skeleton.ARM_PREFIX[arm]
    shoulder, elbow, wrist = _rest_world(rig, [found[prefix + p] for p in ("Arm", "ForeArm", "Hand")])
    return float(np.linalg.norm(elbow - shoulder) + np.linalg.norm(wrist - elbow))


def hand_travel(rig, arm, frames):
    """The hand's farthest distance from where it starts, in arm lengths, and its path (F, 3)."""
    hand = roles(rig)[gesture.skeleton.ARM_PREFIX[arm] + "Hand"]
    path = []
    for frame in frames:
        bpy.context.scene.frame_set(int(frame))
        path.append(_world_heads(rig, [hand])[0])
    path = np.array(path)
    return float(np.linalg.norm(path - path[0], axis=1).max() / arm_length(rig, arm)), path


def point_misses(rig, settings, count, exact_aim, seed, frames=120):
    """Hold misses (degrees) and hand travels (arm lengths) of `count` Point gestures 200 frames apart,
    arms alternating, at unseen targets drawn with seed."""
    rng = np.random.default_rng(seed)
    misses, travels = [], []
    for k in range(count):
        arm, start = ("RIGHT", "LEFT")[k % 2], 1 + 200 * k
        location = world_target(rig, arm, rng)
        target = helpers.add_empty(f"Target{k}", location)
        assert helpers.generate(rig, settings, behaviour="POINT", arm=arm, target=target, start_frame=start,
                                frame_count=frames, exact_aim=exact_aim) == {"FINISHED"}
        played = np.arange(start, start + frames)
        misses.append(hold_miss(rig, *finger_angles(rig, arm, location, played)))
        travels.append(hand_travel(rig, arm, played)[0])
    return np.array(misses), np.array(travels)


def lateral_wrist(rig, arm, frames):
    """(F,) the waving wrist's side-to-side position relative to its shoulder, in arm lengths."""
    found = roles(rig)
    prefix = gesture.skeleton.ARM_PREFIX[arm]
    frame = gesture.character_frame({r: np.array(rig.data.bones[b].head_local) for r, b in found.items()})
    out = []
    for f in frames:
        bpy.context.scene.frame_set(int(f))
        wrist, shoulder = (np.array(rig.pose.bones[found[prefix + n]].head) for n in ("Hand", "Arm"))
        out.append((frame @ (wrist - shoulder))[0])
    return np.array(out) / arm_length(rig, arm) * rig.matrix_world.to_scale()[0]


def wave(rig, settings, arm, start=1001, frames=150):
    """(strokes, hand travel in arm lengths) of a Wave (exaggeration 0.8), measured as played."""
    from test_rig_variants import _strokes

    assert helpers.generate(rig, settings, behaviour="WAVE", arm=arm, exaggeration=0.8, start_frame=start,
                            frame_count=frames) == {"FINISHED"}
    played = np.arange(start, start + frames)
    return _strokes(lateral_wrist(rig, arm, played)), hand_travel(rig, arm, played)[0]


def measured_bones_deform(rig, arm):
    """The hand and index base the measures read are bones the mesh deforms with."""
    found = roles(rig)
    prefix = gesture.skeleton.ARM_PREFIX[arm]
    wanted = {found[prefix + "Hand"], index_joints(rig, arm)[0]}
    return wanted <= deforming_bones(rig)



def arm_drop(rig, arm, frame):
    """Degrees the upper arm (shoulder to elbow joint) points below the character's horizontal at a frame:
    about 0 in a T-pose, 75 in the standing pose a still rig starts and ends in."""
    found = roles(rig)
    prefix = gesture.skeleton.ARM_PREFIX[arm]
    frame_rotation = gesture.character_frame({r: np.array(rig.data.bones[b].head_local) for r, b in found.items()})
    bpy.context.scene.frame_set(int(frame))
    shoulder, elbow = (np.array(rig.pose.bones[found[prefix + n]].head) for n in ("Arm", "ForeArm"))
    direction = frame_rotation @ (elbow - shoulder)
    return math.degrees(math.asin(-direction[2] / np.linalg.norm(direction)))
