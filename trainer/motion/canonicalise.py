"""Canonicalisation: a source skeleton's motion brought onto the canonical rig by world bone directions (numpy).

("Retarget" in this project means the other way: canonical rotations onto the user's rig, core/gesture.py.)

Input: for each canonical bone the source has (named through a core.bone_maps.BoneMap), its world
rotation frame per frame, (F, 3, 3) with columns the bone's X, Y, Z axes and Y along the bone (head
to child), in the character frame (+Z up, facing -Y, left at +X), plus the same frame in a
calibration pose that corresponds to the canonical rest (the source's rest T-pose, or the first frame
of a capture that starts standing).

Each canonical bone then takes the source bone's world direction and its twist:
    T_t = S_t @ B,   B = S_cal^T @ swing(c_y -> s_cal_y) @ C
where C is the canonical rest frame and swing the shortest rotation between the two rest directions.
B turns about the bone's own Y axis only, so T_t's Y axis is exactly the source direction S_t[:, 1];
the twist about it follows the source's twist relative to the calibration pose. When the source's
rest frames equal the canonical ones, B = I and the local rotations transfer unchanged; when they
differ only by roll, this is the rest-orientation difference R_canonical = C^-1 R_src C.

Local rotations follow from the canonical chain (pose = parent_pose @ parent_rest^-1 @ rest @ basis,
as core.kinematics): basis = (parent_pose @ parent_rest^-1 @ rest)^-1 @ T. The Hips stay at rest (the
action space has no root), so a source hip rotation ends up in the Spine. A canonical bone the source
lacks (BoneMap.shared_bend, e.g. Spine1) shares the bend: its partner (Spine) turns half of its
rotation, and it turns the rest so that it ends with the source bone's full orientation.
"""
import numpy as np

from rlanimate_addon.core import rotations, skeleton

_REST = {bone.name: skeleton.rest_frame(bone) for bone in skeleton.BONES}


def canonical_rest_frame(name):
    """(3, 3) the canonical bone's rest frame in the character frame (columns X, Y, Z)."""
    return _REST[name]


def swing(from_dir, to_dir):
    """(3, 3) shortest rotation taking unit vector `from_dir` to unit vector `to_dir`."""
    a = np.asarray(from_dir, dtype=np.float64)
    b = np.asarray(to_dir, dtype=np.float64)
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    axis = np.cross(a, b)
    sin, cos = np.linalg.norm(axis), np.clip(np.dot(a, b), -1.0, 1.0)
    if sin < 1e-12:
        if cos > 0:
            return np.eye(3)
        perpendicular = np.cross(a, (1.0, 0.0, 0.0) if abs(a[0]) < 0.9 else (0.0, 1.0, 0.0))
        return rotations.rotvec_to_matrix(np.pi * perpendicular / np.linalg.norm(perpendicular))
    return rotations.rotvec_to_matrix(axis / sin * np.arctan2(sin, cos))


def source_to_character_frame(hips, head, left_shoulder, right_shoulder):
    """(3, 3) rotation from the source's world into the character frame, from its calibration pose.

    It turns the axis nearest to hips->head onto +Z (so Y-up and Z-up files both stand up; a lean in
    the calibration pose is kept) and then about +Z so the right->left shoulder line points to +X.
    """
    up = np.asarray(head, dtype=np.float64) - np.asarray(hips, dtype=np.float64)
    axis = int(np.argmax(np.abs(up)))
    up_axis = np.zeros(3)
    up_axis[axis] = np.sign(up[axis])
    stand = swing(up_axis, (0.0, 0.0, 1.0))
    across = stand @ (np.asarray(left_shoulder, dtype=np.float64) - np.asarray(right_shoulder, dtype=np.float64))
    yaw = np.arctan2(across[1], across[0])
    return rotations.rotvec_to_matrix(np.array([0.0, 0.0, -yaw])) @ stand


def carries_canonical_axes(frames, heads, tolerance_degrees=3.0):
    """True when a source's bones have the canonical local axes, whatever pose `frames` shows.

    frames: {canonical bone: (3, 3)}, heads: {canonical bone: (3,)} of the source in one pose. Each
    child's offset from its parent, seen in the parent's own axes, is fixed by the rig; a branch off
    the bone's line (shoulders off the chest, eyes off the head, fingers off the hand) reveals the
    bone's roll. Needs at least one such branch to say yes.
    """
    branches = 0
    for bone in skeleton.BONES:
        parent = bone.parent
        if parent not in frames or bone.name not in frames:
            continue
        canonical = _REST[parent].T @ np.subtract(bone.head, skeleton.BONE_BY_NAME[parent].head)
        source = frames[parent].T @ (np.asarray(heads[bone.name]) - np.asarray(heads[parent]))
        if np.linalg.norm(canonical) < 1e-6 or np.linalg.norm(source) < 1e-9:
            continue
        canonical, source = canonical / np.linalg.norm(canonical), source / np.linalg.norm(source)
        if np.degrees(np.arccos(np.clip(np.dot(canonical, source), -1.0, 1.0))) > tolerance_degrees:
            return False
        branches += abs(canonical[1]) < 0.99  # off the parent's Y axis
    return branches > 0


def twist_offsets(calibration_frames):
    """{canonical bone: (3, 3) B} from {canonical bone: (3, 3) source frame in the calibration pose}."""
    offsets = {}
    for name, source in calibration_frames.items():
        rest = _REST[name]
        target = swing(rest[:, 1], source[:, 1]) @ rest
        offsets[name] = source.T @ target
    return offsets


def _halve(basis):
    return rotations.rotvec_to_matrix(0.5 * rotations.matrix_to_rotvec(basis))


def local_rotations(source_frames, calibration_frames, shared_bend=None):
    """Canonical local rotation matrices {bone: (F, 3, 3)} for every canonical bone.

    source_frames: {canonical bone: (F, 3, 3)} world frames of the source bones, character frame.
    calibration_frames: {canonical bone: (3, 3)} the same bones in the calibration pose.
    shared_bend: {canonical bone the source lacks: canonical partner bone} (BoneMap.shared_bend).
    Bones with no source stay at rest (identity), apart from shared-bend bones.
    """
    shared_bend = shared_bend or {}
    sources = dict(source_frames)
    calibration = dict(calibration_frames)
    for missing, partner in shared_bend.items():
        if partner in sources and missing not in sources:
            sources[missing] = sources[partner]
            calibration[missing] = calibration[partner]
    halved = {shared_bend[m] for m in shared_bend if m in sources}
    offsets = twist_offsets(calibration)
    frame_count = len(next(iter(sources.values())))
    identity = np.broadcast_to(np.eye(3), (frame_count, 3, 3))
    pose, bases = {}, {}
    for bone in skeleton.BONES:
        rest = _REST[bone.name]
        if bone.parent is None:
            bind = np.broadcast_to(rest, (frame_count, 3, 3))  # (F, 3, 3) pose before the basis
        else:
            bind = pose[bone.parent] @ (_REST[bone.parent].T @ rest)
        if bone.name in sources and bone.parent is not None:
            target = sources[bone.name] @ offsets[bone.name]  # (F, 3, 3)
            basis = np.swapaxes(bind, -1, -2) @ target
            if bone.name in halved:
                basis = _halve(basis)
        else:
            basis = identity
        bases[bone.name] = basis
        pose[bone.name] = bind @ basis
    return bases


def action_rotvecs(bases):
    """(F, 15, 3) rotation vectors of skeleton.ACTION_JOINTS from local_rotations' output."""
    return np.stack([rotations.matrix_to_rotvec(bases[j]) for j in skeleton.ACTION_JOINTS], axis=1)
