"""The bpy-free gesture pipeline: objectives from targets, retargeting, blending, time-scaling."""
import numpy as np
import pytest

from rlanimate_addon.core import gesture, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.rotations import (matrix_to_quat, quat_to_matrix, rotvec_to_matrix,
                                            rotvec_to_quat)

RNG = np.random.default_rng()


def random_rotations(count):
    return rotvec_to_matrix(RNG.normal(size=(count, 3)))


class ReplayAgent:
    """Plays back fixed actions at whatever length it is asked for, and records what it was asked."""

    action_bounds = spaces.DEFAULT_ACTION_BOUNDS
    average_frames = {"POINT": 50, "WAVE": 80}

    def __init__(self, actions):
        self.actions, self.calls = actions, []

    def rollout(self, objectives, seed=None):
        self.calls.append((np.array(objectives), seed))
        return gesture.resample(self.actions, len(objectives))


def test_character_frame_is_identity_on_the_canonical_rig_and_undoes_a_rotated_armature_space():
    heads = gesture.canonical_rig_pose().rest_heads
    assert np.allclose(gesture.character_frame(heads), np.eye(3))
    rotation = random_rotations(1)[0]
    rotated = {name: 37.0 * rotation @ head for name, head in heads.items()}  # other units, other axes
    assert np.allclose(gesture.character_frame(rotated) @ rotation, np.eye(3), atol=1e-9)


def test_pointing_directions_match_the_spaces_definition_whatever_the_rig_scale_and_axes():
    heads = gesture.canonical_rig_pose().rest_heads
    targets = RNG.uniform(-3, 3, size=(5, 3)) + [0, -2, 1.5]
    expected = np.array([spaces.pointing_direction("LEFT", t) for t in targets])
    assert np.allclose(gesture.pointing_directions("LEFT", targets, heads), expected)
    rotation = random_rotations(1)[0]
    rig_heads = {name: 100.0 * rotation @ head for name, head in heads.items()}
    rig_targets = 100.0 * targets @ rotation.T
    assert np.allclose(gesture.pointing_directions("LEFT", rig_targets, rig_heads), expected)
    with pytest.raises(RLAnimateError, match="shoulder"):
        gesture.pointing_directions("RIGHT", [heads["RightArm"]], heads)


def test_retarget_gives_every_bone_the_canonical_armature_space_rotation():
    names = skeleton.ACTION_JOINTS
    to_character = random_rotations(1)[0]
    rig_frames = random_rotations(len(names))  # (15, 3, 3) rest frames that differ from the canonical
    conversions = gesture.retarget_matrices(names, rig_frames, to_character)
    rotvecs = RNG.normal(scale=0.8, size=(4, len(names), 3))
    rig_local = quat_to_matrix(gesture.retarget(rotvecs, conversions))  # (4, 15, 3, 3)
    canonical_frames = np.stack([skeleton.rest_frame(skeleton.BONE_BY_NAME[n]) for n in names])
    canonical_delta = canonical_frames @ rotvec_to_matrix(rotvecs) @ np.swapaxes(canonical_frames, -1, -2)
    rig_delta = to_character @ rig_frames @ rig_local @ np.swapaxes(rig_frames, -1, -2) @ to_character.T
    assert np.allclose(rig_delta, canonical_delta, atol=1e-9)
    same = gesture.retarget_matrices(names, canonical_frames, np.eye(3))
    assert np.allclose(np.abs(np.sum(gesture.retarget(rotvecs, same) * rotvec_to_quat(rotvecs), axis=-1)), 1.0)


@pytest.mark.parametrize("count", [2, 3, 30, 121])
def test_blend_weights_start_and_end_at_the_start_pose_and_reach_the_gesture(count):
    weights = gesture.blend_weights(count)
    assert weights[0] == 0.0 and weights[-1] == 0.0
    assert np.all((weights >= 0) & (weights <= 1))
    if count >= 5:
        assert weights.max() == 1.0
        half = weights[: count // 2 + 1]
        assert np.all(np.diff(half) >= 0), "the blend-in must not go back"


def test_slerp_ends_and_midpoint_and_blend_from_pose():
    q0, q1 = rotvec_to_quat(RNG.normal(size=(6, 3))), rotvec_to_quat(RNG.normal(size=(6, 3)))
    assert np.allclose(np.abs(np.sum(gesture.slerp(q0, q1, np.zeros(6)) * q0, axis=-1)), 1.0)
    assert np.allclose(np.abs(np.sum(gesture.slerp(q0, q1, np.ones(6)) * q1, axis=-1)), 1.0)
    middle = gesture.slerp(q0, q1, np.full(6, 0.5))
    angle = lambda a, b: 2 * np.arccos(np.clip(np.abs(np.sum(a * b, axis=-1)), 0, 1))  # noqa: E731
    assert np.allclose(angle(q0, middle), angle(middle, q1), atol=1e-9)
    blended = gesture.blend_from_pose(q0[:2], np.stack([q1[:2]] * 5), np.array([0, 0.25, 1, 0.25, 0]))
    assert np.allclose(np.abs(np.sum(blended[0] * q0[:2], axis=-1)), 1.0)
    assert np.allclose(np.abs(np.sum(blended[2] * q1[:2], axis=-1)), 1.0)


def test_continuous_removes_sign_flips_without_changing_rotations():
    quats = rotvec_to_quat(np.cumsum(RNG.normal(scale=0.2, size=(40, 3, 3)), axis=0))
    flipped = quats * RNG.choice([-1.0, 1.0], size=(40, 3, 1))
    fixed = gesture.continuous(flipped)
    assert np.all(np.sum(fixed[1:] * fixed[:-1], axis=-1) > 0)
    assert np.allclose(quat_to_matrix(fixed), quat_to_matrix(quats), atol=1e-12)


def test_resample_keeps_the_ends_and_interpolates_linearly():
    values = RNG.normal(size=(7, 2))
    out = gesture.resample(values, 13)
    assert out.shape == (13, 2)
    assert np.allclose(out[0], values[0]) and np.allclose(out[-1], values[-1])
    assert np.allclose(out[2], values[1])


def _request(behaviour="WAVE", arm="RIGHT", frames=60, **kwargs):
    return gesture.GestureRequest(behaviour, arm, frames, **kwargs)


def test_lengths_outside_the_supported_range_are_time_scaled_from_the_nearest_supported_length():
    actions = RNG.uniform(0.3, 0.7, size=(80, spaces.ACTION_SIZE))
    agent = ReplayAgent(actions)
    rig = gesture.canonical_rig_pose()
    shortest, longest = gesture.supported_length_range(agent.average_frames["WAVE"])
    assert (shortest, longest) == (32, 120)
    for frames, steps in ((10, shortest), (60, 60), (400, longest)):
        names, quats = gesture.gesture_rotations(agent, _request(frames=frames, seed=3), rig)
        objectives, seed = agent.calls[-1]
        assert len(objectives) == steps and seed == 3
        assert np.allclose(objectives[[0, -1], spaces.OBJECTIVE_TIME], [0.0, 1.0])
        assert quats.shape == (frames, len(names), 4)
    assert names == skeleton.ACTION_JOINTS


def test_pointing_adds_the_hand_shape_and_the_gesture_starts_and_ends_at_the_start_pose():
    agent = ReplayAgent(RNG.uniform(0.2, 0.8, size=(50, spaces.ACTION_SIZE)))
    rig = gesture.canonical_rig_pose()
    start = rotvec_to_quat(RNG.normal(scale=0.3, size=(len(skeleton.BONES), 3)))
    rig.start_quats = dict(zip(skeleton.BONE_NAMES, start))
    targets = np.tile([-1.0, -2.0, 1.6], (50, 1))
    names, quats = gesture.gesture_rotations(agent, _request("POINT", frames=50, targets=targets), rig)
    assert names[:15] == skeleton.ACTION_JOINTS
    assert {"RightHandMiddle2", "RightHandPinky1", "RightHandThumb1"} <= set(names[15:])
    assert not any(n.startswith("Left") for n in names[15:])
    expected = np.array([rig.start_quats[n] for n in names])
    for frame in (0, -1):
        assert np.allclose(np.abs(np.sum(quats[frame] * expected, axis=-1)), 1.0)
    objectives, _ = agent.calls[-1]
    assert np.allclose(objectives[:, spaces.OBJECTIVE_ATTRIBUTES], spaces.pointing_direction("RIGHT", targets[0]))


def test_pointing_hand_curls_the_other_fingers_towards_the_palm():
    from rlanimate_addon.core import kinematics

    for arm in skeleton.ARMS:
        names, rotvecs = gesture.pointing_hand_rotations(arm, 1)
        pose = kinematics.head_positions(kinematics.pose_matrices(dict(zip(names, rotvecs[0]))))
        rest = kinematics.head_positions(kinematics.pose_matrices({}))
        prefix = skeleton.ARM_PREFIX[arm]
        for finger in ("Middle", "Ring", "Pinky"):
            tip = kinematics.bone_index(f"{prefix}Hand{finger}4")
            assert pose[tip, 2] < rest[tip, 2] - 0.02, f"{arm} {finger} must curl down, towards the palm"


@pytest.mark.parametrize("request_kwargs, message", [
    (dict(behaviour="POINT", targets=None), "needs a target"),
    (dict(frames=1), "at least 2 frames"),
    (dict(frames=0), "at least 2 frames"),
])
def test_bad_requests_raise_before_the_agent_runs(request_kwargs, message):
    agent = ReplayAgent(RNG.uniform(size=(10, spaces.ACTION_SIZE)))
    with pytest.raises(RLAnimateError, match=message):
        gesture.gesture_rotations(agent, _request(**request_kwargs), gesture.canonical_rig_pose())
    assert agent.calls == []


def test_a_rig_without_required_bones_is_named_in_the_error():
    rig = gesture.canonical_rig_pose()
    del rig.rest_heads["LeftHandIndex4"], rig.rest_heads["Neck"]
    with pytest.raises(RLAnimateError, match="LeftHandIndex4, Neck"):
        gesture.gesture_rotations(ReplayAgent(np.zeros((5, 45))), _request(), rig)


def test_an_agent_returning_the_wrong_shape_is_reported():
    agent = ReplayAgent(np.full((60, 44), 0.5))
    with pytest.raises(RLAnimateError, match="shape"):
        gesture.gesture_rotations(agent, _request(), gesture.canonical_rig_pose())


def test_matrix_quat_helpers_agree():
    m = random_rotations(3)
    assert np.allclose(quat_to_matrix(matrix_to_quat(m)), m)


def test_exact_aim_off_keys_the_agents_own_aim():
    """With exact_aim the pointing arm is turned (aim correction); without it the keys are the
    agent's own rotations, and nothing else differs."""
    agent = ReplayAgent(np.random.default_rng(4).uniform(0.3, 0.7, size=(50, spaces.ACTION_SIZE)))
    rig = gesture.canonical_rig_pose()
    targets = np.tile([-1.0, -2.0, 1.6], (50, 1))
    names, aimed = gesture.gesture_rotations(agent, _request("POINT", frames=50, targets=targets), rig)
    raw_names, raw = gesture.gesture_rotations(
        agent, _request("POINT", frames=50, targets=targets, exact_aim=False), rig)
    assert names == raw_names
    changed = {names[b] for b in range(len(names)) if not np.allclose(np.abs(aimed[:, b]), np.abs(raw[:, b]))}
    assert changed == {"RightArm"}
    # on the canonical rig retargeting is the identity: where the blend is full, the raw keys are the
    # agent's decoded actions
    expected = rotvec_to_quat(spaces.decode_action(agent.actions))  # (50, 15, 4)
    full = int(np.argmax(gesture.blend_weights(50)))
    arm = names.index("RightArm")
    assert abs(np.sum(raw[full, arm] * expected[full, arm])) == pytest.approx(1.0, abs=1e-9)
