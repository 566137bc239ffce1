"""Canonicalisation by world bone directions, and the real Bandai Namco capture through Blender's importer."""

import numpy as np
import pytest

from rlanimate_addon.core import bone_maps, kinematics, rotations, skeleton
from trainer.motion import canonicalise
from trainer.paths import REALMOCAP_DIR

_REST = {b.name: skeleton.rest_frame(b) for b in skeleton.BONES}


def random_local_rotations(rng, frames, scale=0.4):
    return {name: rng.normal(0.0, scale, (frames, 3)) for name in skeleton.BONE_NAMES if name != "Hips"}


def world_frames(local):
    """{bone: (F, 3, 3)} canonical world frames (columns X, Y, Z; Y along the bone) from local rotations."""
    pose = kinematics.pose_matrices(local)  # (F, B, 4, 4)
    return {name: pose[:, kinematics.bone_index(name), :3, :3] for name in skeleton.BONE_NAMES}


def angle_degrees(a, b):
    """Angle between vectors; atan2 keeps it exact near 0, where arccos of the cosine has a 1e-6 deg floor."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1)))


def test_swing_is_the_shortest_rotation_between_directions():
    rng = np.random.default_rng(0)
    for _ in range(20):
        a, b = rng.normal(size=3), rng.normal(size=3)
        turn = canonicalise.swing(a, b)
        np.testing.assert_allclose(turn @ (a / np.linalg.norm(a)), b / np.linalg.norm(b), atol=1e-12)
        axis = rotations.matrix_to_rotvec(turn)
        assert abs(np.dot(axis, a)) < 1e-9 and abs(np.dot(axis, b)) < 1e-9  # turns about a x b only
    np.testing.assert_allclose(canonicalise.swing((0, 0, 1), (0, 0, -1)) @ (0, 0, 1), (0, 0, -1), atol=1e-12)


def test_source_to_character_frame_stands_a_y_up_skeleton_facing_anywhere():
    # A Y-up skeleton facing +X (its left at -Z): the correction must map up to +Z and left to +X.
    correction = canonicalise.source_to_character_frame(
        hips=(0, 1, 0), head=(0, 1.6, 0), left_shoulder=(0.1, 1.4, -0.2), right_shoulder=(0.1, 1.4, 0.2)
    )
    np.testing.assert_allclose(correction @ (0, 1, 0), (0, 0, 1), atol=1e-12)
    np.testing.assert_allclose(correction @ (0, 0, -1), (1, 0, 0), atol=1e-12)
    np.testing.assert_allclose(correction @ correction.T, np.eye(3), atol=1e-12)


def test_source_with_canonical_rest_frames_transfers_local_rotations_unchanged():
    local = random_local_rotations(np.random.default_rng(1), 6)
    bases = canonicalise.local_rotations(world_frames(local), _REST)
    for name, rotvec in local.items():
        np.testing.assert_allclose(bases[name], rotations.rotvec_to_matrix(rotvec), atol=1e-9, err_msg=name)
    np.testing.assert_allclose(canonicalise.action_rotvecs(bases),
                               np.stack([local[j] for j in skeleton.ACTION_JOINTS], axis=1), atol=1e-9)


def test_source_bones_with_other_rolls_transfer_as_the_rest_orientation_difference():
    rng = np.random.default_rng(2)
    local = random_local_rotations(rng, 5)
    rolls = {name: rotations.rotvec_to_matrix((0.0, rng.uniform(-np.pi, np.pi), 0.0)) for name in skeleton.BONE_NAMES}
    frames = {name: f @ rolls[name] for name, f in world_frames(local).items()}  # source rest = canonical @ roll
    calibration = {name: _REST[name] @ rolls[name] for name in skeleton.BONE_NAMES}
    bases = canonicalise.local_rotations(frames, calibration)
    for name in skeleton.ACTION_JOINTS:
        np.testing.assert_allclose(bases[name], rotations.rotvec_to_matrix(local[name]), atol=1e-9, err_msg=name)


def test_a_source_in_another_rest_pose_keeps_every_bone_direction():
    # Calibrated in a hanging-arms pose instead of the T-pose: directions must still follow the source.
    rng = np.random.default_rng(3)
    hanging = {name: np.zeros((1, 3)) for name in skeleton.BONE_NAMES if name != "Hips"}
    hanging["LeftArm"][:] = (-1.2, 0.0, 0.0)
    hanging["RightArm"][:] = (-1.2, 0.0, 0.0)
    calibration = {name: f[0] for name, f in world_frames(hanging).items()}
    source = world_frames(random_local_rotations(rng, 4))
    pose = kinematics.pose_matrices({n: rotations.matrix_to_rotvec(b) for n, b in
                                     canonicalise.local_rotations(source, calibration).items()})
    for name in skeleton.ACTION_JOINTS:
        got = pose[:, kinematics.bone_index(name), :3, 1]
        assert angle_degrees(got, source[name][:, :, 1]).max() < 1e-6, name


def test_missing_spine1_shares_the_bend_with_spine():
    rng = np.random.default_rng(4)
    source = world_frames(random_local_rotations(rng, 5, scale=0.3))
    # The source's one spine bone spans canonical Spine and Spine1: it carries Spine1's world frame.
    source["Spine"] = source.pop("Spine1")
    bases = canonicalise.local_rotations(source, _REST, shared_bend={"Spine1": "Spine"})
    pose = kinematics.pose_matrices({n: rotations.matrix_to_rotvec(b) for n, b in bases.items()})
    np.testing.assert_allclose(pose[:, kinematics.bone_index("Spine1"), :3, :3], source["Spine"], atol=1e-9)
    for name in ("Spine2", "Neck", "LeftArm", "RightHand"):
        np.testing.assert_allclose(pose[:, kinematics.bone_index(name), :3, :3], source[name], atol=1e-9)
    # Spine turns half of the bend (relative to its rest under the Hips), Spine1 the rest of it.
    full_bend = _REST["Spine"].T @ source["Spine"]
    np.testing.assert_allclose(bases["Spine"] @ bases["Spine"], full_bend, atol=1e-9)
    assert np.linalg.norm(rotations.matrix_to_rotvec(bases["Spine1"]), axis=-1).max() > 0.05


# --- the real capture, through Blender's BVH importer -----------------------------------------------

def _bandai_clip():
    clips = sorted((REALMOCAP_DIR / "wave").glob("*.bvh")) if REALMOCAP_DIR.is_dir() else []
    if not clips:
        pytest.skip(f"real motion capture not found at {REALMOCAP_DIR.resolve()}: the Bandai Namco canonicalisation "
                    "test needs ../shared/realmocap/ beside the repository")
    return next(p for p in clips if "right-hand_active_002" in p.name)


def test_canonicalising_a_real_bandai_namco_wave_keeps_world_bone_directions():
    pytest.importorskip("bpy")
    from trainer.blender_io import clip_import, rig_session

    path = _bandai_clip()
    rig_session.new_empty_scene()
    clip = clip_import.import_clip(path)

    # Source directions straight from the imported joints: from each joint to its child's joint.
    import bpy
    rig_session.new_empty_scene()
    bpy.ops.import_anim.bvh(filepath=str(path), update_scene_fps=True)
    rig = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    scene = bpy.context.scene
    start, end = (int(round(v)) for v in rig.animation_data.action.frame_range)
    links = {"Spine": ("Chest", "Neck"), "Neck": ("Neck", "Head")}
    for side in ("L", "R"):
        links[f"{'Left' if side == 'L' else 'Right'}Shoulder"] = (f"Shoulder_{side}", f"UpperArm_{side}")
        links[f"{'Left' if side == 'L' else 'Right'}Arm"] = (f"UpperArm_{side}", f"LowerArm_{side}")
        links[f"{'Left' if side == 'L' else 'Right'}ForeArm"] = (f"LowerArm_{side}", f"Hand_{side}")
    links["Spine2"] = links.pop("Spine")
    links["Spine1"] = ("Spine", "Chest")  # the source's one spine bone; canonical Spine shares its bend
    heads = {name: [] for name in bone_maps.BANDAI_NAMCO.to_canonical}
    for frame in range(start, end + 1):
        scene.frame_set(frame)
        for name in heads:
            heads[name].append(np.array(rig.matrix_world @ rig.pose.bones[name].head))
    heads = {name: np.array(v) for name, v in heads.items()}  # (F, 3) each
    facing = canonicalise.source_to_character_frame(heads["Hips"][0], heads["Head"][0], heads["UpperArm_L"][0],
                                      heads["UpperArm_R"][0])

    pose = kinematics.pose_matrices({j: clip.rotvecs[:, k] for k, j in enumerate(skeleton.ACTION_JOINTS)})
    assert len(pose) == len(heads["Hips"])
    worst = {}
    for canonical, (joint, child) in links.items():
        source = (heads[child] - heads[joint]) @ facing.T
        target = pose[:, kinematics.bone_index(canonical), :3, 1]
        worst[canonical] = angle_degrees(source, target).max()
    assert max(worst.values()) < 2.0, worst
    # The waving arm really moves: the test is not passing on a still pose.
    wrist = heads["Hand_R"] - heads["UpperArm_R"]
    assert np.ptp(wrist[:, 1]) > 20.0  # centimetres of vertical hand travel


def test_canonical_axes_are_recognised_in_any_pose_and_other_rolls_are_not():
    rng = np.random.default_rng(5)
    local = random_local_rotations(rng, 1, scale=0.6)
    frames = {name: f[0] for name, f in world_frames(local).items()}
    pose = kinematics.pose_matrices(local)[0]
    heads = {name: pose[kinematics.bone_index(name), :3, 3] for name in skeleton.BONE_NAMES}
    assert canonicalise.carries_canonical_axes(frames, heads)
    rolled = dict(frames, Spine2=frames["Spine2"] @ rotations.rotvec_to_matrix((0.0, 0.3, 0.0)))
    assert not canonicalise.carries_canonical_axes(rolled, heads)
