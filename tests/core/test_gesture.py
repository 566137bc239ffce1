"""The bpy-free gesture pipeline: objectives from targets, retargeting, blending, time-scaling."""
import numpy as np
import pytest

from rlanimate_addon.core import aim, gesture, skeleton, spaces
from rlanimate_addon.core.behaviours import AIMS, TARGET, Behaviour
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.rotations import (
    continuous,
    matrix_to_quat,
    quat_multiply,
    quat_to_matrix,
    rotvec_to_matrix,
    rotvec_to_quat,
)

RNG = np.random.default_rng(11)


def random_rotations(count):
    return rotvec_to_matrix(RNG.normal(size=(count, 3)))


class ReplayAgent:
    """Plays back fixed actions at whatever length it is asked for, and records what it was asked."""

    action_bounds = spaces.DEFAULT_ACTION_BOUNDS
    average_frames = {"POINT": 50, "WAVE": 80}
    space = spaces.PAPER_SPACE
    still_free_arm = frozenset()

    def kind(self, behaviour):
        return self.space.kind(behaviour)

    def __init__(self, actions):
        self.actions, self.calls = actions, []

    def rollout(self, objectives, seed=None):
        self.calls.append((np.array(objectives), seed))
        return gesture.resample(self.actions, len(objectives))

    def wave_rhythm(self, exaggeration, frame_count, seed=None, tempo=None, arm=None):
        return None  # the paper's wave objective


def test_character_frame_is_identity_on_the_canonical_rig_and_undoes_a_rotated_armature_space():
    heads = gesture.canonical_rig().rest_heads
    assert np.allclose(gesture.character_frame(heads), np.eye(3))
    rotation = random_rotations(1)[0]
    rotated = {name: 37.0 * rotation @ head for name, head in heads.items()}  # other units, other axes
    assert np.allclose(gesture.character_frame(rotated) @ rotation, np.eye(3), atol=1e-9)


def test_pointing_directions_match_the_spaces_definition_whatever_the_rig_scale_and_axes():
    heads = gesture.canonical_rig().rest_heads
    targets = RNG.uniform(-3, 3, size=(5, 3)) + [0, -2, 1.5]
    expected = np.array([spaces.pointing_direction("LEFT", t) for t in targets])
    assert np.allclose(gesture.pointing_directions("LEFT", targets, heads), expected)
    rotation = random_rotations(1)[0]
    rig_heads = {name: 100.0 * rotation @ head for name, head in heads.items()}
    rig_targets = 100.0 * targets @ rotation.T
    assert np.allclose(gesture.pointing_directions("LEFT", rig_targets, rig_heads), expected)
    with pytest.raises(RLAnimateError, match="shoulder"):
        gesture.pointing_directions("RIGHT", [heads["RightArm"]], heads)


def test_a_target_within_the_arms_reach_is_refused_on_rigs_with_and_without_index_bones():
    heads = {name: 100.0 * head for name, head in gesture.canonical_rig().rest_heads.items()}  # centimetres
    fingerless = {name: head for name, head in heads.items() if "Index" not in name}
    shoulder = heads["RightArm"]
    reach = np.linalg.norm(heads["RightHandIndex1"] - shoulder)
    assert gesture.arm_reach("RIGHT", fingerless) == pytest.approx(gesture.arm_reach("RIGHT", heads)) == \
        pytest.approx(reach)
    ahead = np.array([0.0, -1.0, 0.0])  # the character faces -Y
    for rig in (heads, fingerless):
        with pytest.raises(RLAnimateError, match="within the right arm's reach \\(at its closest 90% of the way"):
            gesture.pointing_directions("RIGHT", [shoulder + 2.0 * reach * ahead, shoulder + 0.9 * reach * ahead], rig)
        assert np.allclose(gesture.pointing_directions("RIGHT", [shoulder + 1.2 * reach * ahead], rig), [ahead])


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
    fixed = continuous(flipped)
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
    rig = gesture.canonical_rig()
    shortest, longest = gesture.supported_length_range(agent.average_frames["WAVE"])
    assert (shortest, longest) == (32, 120)
    for frames, steps in ((10, shortest), (60, 60), (400, longest)):
        names, quats, _ = gesture.gesture_rotations(agent, _request(frames=frames, seed=3), rig)
        objectives, seed = agent.calls[-1]
        assert len(objectives) == steps and seed == 3
        assert np.allclose(objectives[[0, -1], spaces.OBJECTIVE_TIME], [0.0, 1.0])
        assert quats.shape == (frames, len(names), 4)
    assert names == skeleton.ACTION_JOINTS


def test_a_point_shorter_than_the_agents_average_is_its_average_point_played_faster():
    agent = ReplayAgent(RNG.uniform(0.3, 0.7, size=(80, spaces.ACTION_SIZE)))
    average = agent.average_frames["POINT"]
    for frames, steps in ((30, average), (average, average), (70, 70)):
        gesture.run_agent(agent, "POINT", spaces.PAPER_SPACE.make_objective("POINT", "RIGHT", [0.0, -1.0, 0.0], frames))
        assert len(agent.calls[-1][0]) == steps
    assert gesture.rollout_length(30, average, "intensity") == 30, "a quick wave is the agent's own"
    assert gesture.rollout_length(30, average, "target") == average, "as is any target behaviour's"


def _animated(rig, frames, scale=0.3):
    """The rig with a random pose underneath at every frame (as its own animation would play)."""
    under = np.tile(np.eye(4), (frames, len(skeleton.BONES), 1, 1))
    under[..., :3, :3] = rotvec_to_matrix(RNG.normal(scale=scale, size=(frames, len(skeleton.BONES), 3)))
    return gesture.RigState(rig.name, rig.skeleton, rig.roles, rig.family, under, animated=True)


def test_pointing_adds_the_hand_shape_and_the_gesture_blends_from_and_to_the_pose_underneath():
    agent = ReplayAgent(RNG.uniform(0.2, 0.8, size=(50, spaces.ACTION_SIZE)))
    rig = _animated(gesture.canonical_rig(), 50)
    targets = np.tile([-1.0, -2.0, 1.6], (50, 1))
    names, quats, under = gesture.gesture_rotations(agent, _request("POINT", frames=50, targets=targets), rig)
    owned = gesture.owned_joints("RIGHT", still=False)
    assert names[:len(owned)] == owned and not any(n.startswith("Left") for n in owned), "the other arm is not keyed"
    assert {"RightHandMiddle2", "RightHandPinky1", "RightHandThumb1"} <= set(names[len(owned):])
    assert not any(n.startswith("Left") for n in names[len(owned):-2]) and names[-2:] == ("LeftEye", "RightEye")
    columns = [skeleton.BONE_NAMES.index(n) for n in names]
    expected = matrix_to_quat(rig.under[:, columns, :3, :3])
    assert np.allclose(np.abs(np.sum(under * expected, axis=-1)), 1.0)
    for frame in (0, -1):
        assert np.allclose(np.abs(np.sum(quats[frame] * expected[frame], axis=-1)), 1.0)
    objectives, _ = agent.calls[-1]
    hips = rig.skeleton.index["Hips"]
    back = rig.skeleton.rest[hips] @ np.linalg.inv(rig.under_pose[:, hips])  # (50, 4, 4): the hips' motion undone
    carried = np.einsum("nij,nj->ni", back, np.concatenate([targets, np.ones((50, 1))], axis=1))[:, :3]
    assert np.allclose(objectives[:, spaces.OBJECTIVE_ATTRIBUTES],
                       [spaces.pointing_direction("RIGHT", t) for t in carried])


def test_point_asks_the_agent_for_the_direction_the_body_sees_over_hips_that_turn_underneath():
    frames, turn = 40, np.radians(30.0)
    rig = gesture.canonical_rig()
    under = np.tile(np.eye(4), (frames, len(skeleton.BONES), 1, 1))
    hips = rig.skeleton.index["Hips"]
    frame = skeleton.rest_frame(skeleton.BONE_BY_NAME["Hips"])  # local axes of the hips at rest
    under[:, hips, :3, :3] = frame.T @ rotvec_to_matrix(np.array([0.0, 0.0, turn])) @ frame  # a turn to its left
    turned = gesture.RigState(rig.name, rig.skeleton, rig.roles, rig.family, under, animated=True)
    target = np.array([-1.0, -2.5, 1.5])
    agent = ReplayAgent(RNG.uniform(0.2, 0.8, size=(frames, spaces.ACTION_SIZE)))
    gesture.gesture_rotations(agent, _request("POINT", frames=frames, targets=target), turned)
    asked = agent.calls[-1][0][:, spaces.OBJECTIVE_ATTRIBUTES]
    hips_head = np.array(skeleton.BONE_BY_NAME["Hips"].head)
    seen = hips_head + rotvec_to_matrix(np.array([0.0, 0.0, -turn])) @ (target - hips_head)
    assert np.allclose(asked, spaces.pointing_direction("RIGHT", seen), atol=1e-9)
    gesture.gesture_rotations(agent, _request("POINT", frames=frames, targets=target), rig)  # hips at rest
    assert np.allclose(agent.calls[-1][0][:, spaces.OBJECTIVE_ATTRIBUTES], spaces.pointing_direction("RIGHT", target))


@pytest.mark.parametrize("noise", [0.0, 1e-4])
def test_a_still_rig_at_rest_starts_and_ends_in_the_standing_pose_not_its_bind_pose(noise):
    """noise: radians about each axis in every bone's basis underneath, as a rest pose read back from
    float32 bind matrices leaves: still at rest, so still the standing pose."""
    agent = ReplayAgent(RNG.uniform(0.2, 0.8, size=(40, spaces.ACTION_SIZE)))
    rig = gesture.canonical_rig()
    rig.under[:, :3, :3] = rotvec_to_matrix(np.tile([noise, -noise, noise], (len(rig.under), 1)))
    names, quats, _ = gesture.gesture_rotations(agent, _request(frames=40), rig)
    hanging = {n: rotvec_to_quat(gesture.STANDING_POSE.get(n, np.zeros(3))) for n in names}
    for frame in (0, -1):
        assert np.allclose([abs(np.dot(quats[frame, k], hanging[n])) for k, n in enumerate(names)], 1.0)
    from rlanimate_addon.core import kinematics

    pose = kinematics.pose_matrices({n: gesture.STANDING_POSE[n] for n in gesture.STANDING_POSE})
    heads = kinematics.head_positions(pose)
    for side in ("Left", "Right"):
        wrist, shoulder = heads[kinematics.bone_index(side + "Hand")], heads[kinematics.bone_index(side + "Arm")]
        assert wrist[2] < shoulder[2] - 0.4, f"the {side} arm must hang down"
        assert wrist[1] < shoulder[1], f"the {side} forearm must bend forward"


@pytest.mark.parametrize("arm", skeleton.ARMS)
def test_exact_aim_puts_the_target_on_the_rig_finger_line_over_animation_underneath(arm):
    frames = 60
    agent = ReplayAgent(RNG.uniform(0.3, 0.7, size=(frames, spaces.ACTION_SIZE)))
    rig = _animated(gesture.canonical_rig(), frames, scale=0.1)
    target = np.array([-1.0 if arm == "RIGHT" else 1.0, -2.5, 1.7])
    names, quats, _ = gesture.gesture_rotations(
        agent, _request("POINT", arm, frames, targets=np.tile(target, (frames, 1))), rig
    )
    basis = rig.under.copy()
    columns = [rig.skeleton.index[n] for n in names]
    basis[:, columns, :3, :3] = quat_to_matrix(quats)
    line = gesture.finger_line_bones(rig.roles, arm)
    base, tip = line.points(rig.skeleton, rig.skeleton.pose_matrices(basis, only=(line.end,)))
    finger, to_target = tip - base, target - base
    cos = np.sum(finger * to_target, axis=1) / np.linalg.norm(finger, axis=1) / np.linalg.norm(to_target, axis=1)
    angles = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    phase = aim.pointing_phase(gesture.played_finger_base(gesture.run_agent(agent, "POINT", agent.calls[-1][0]), arm))
    assert angles[phase == 1.0].max() < 0.01, "at full weight the finger line must pass through the target"


@pytest.mark.parametrize("animated", [False, True])
def test_the_eyes_look_at_the_target_while_pointing(animated):
    frames = 60
    agent = ReplayAgent(RNG.uniform(0.3, 0.7, size=(frames, spaces.ACTION_SIZE)))
    rig = _animated(gesture.canonical_rig(), frames, scale=0.1) if animated else gesture.canonical_rig()
    target = np.array([-1.5, -2.5, 0.8])
    names, quats, _ = gesture.gesture_rotations(agent, _request("POINT", "RIGHT", frames,
                                                                targets=np.tile(target, (frames, 1))), rig)
    basis = rig.under_at(frames).copy()
    basis[:, [rig.skeleton.index[n] for n in names], :3, :3] = quat_to_matrix(quats)
    pose = rig.skeleton.pose_matrices(basis, only=("LeftEye", "RightEye"))
    phase = aim.pointing_phase(
        gesture.played_finger_base(gesture.run_agent(agent, "POINT", agent.calls[-1][0]), "RIGHT")
    )
    for eye in ("LeftEye", "RightEye"):
        i = rig.skeleton.index[eye]
        looking = pose[:, i, :3, :3] @ (skeleton.rest_frame(skeleton.BONE_BY_NAME[eye]).T @ [0.0, -1.0, 0.0])
        wanted = target - pose[:, i, :3, 3]
        cos = np.sum(looking * wanted, axis=1) / np.linalg.norm(wanted, axis=1)
        angles = np.degrees(np.arccos(np.clip(cos, -1, 1)))
        assert angles[phase == 1.0].max() < 0.01, f"{eye} must look at the target at full weight"
        assert angles[0] > 5.0, "and only then: at the start it looks ahead"


@pytest.mark.parametrize("missing, above", [("Spine2", "Neck"), ("RightShoulder", "RightArm")])
def test_a_missing_spine_or_collar_bone_is_folded_and_the_bone_above_turns_the_same(missing, above):
    """A missing spine joint folds into the one below; a missing collar into its upper arm, which then
    points where the canonical upper arm points (an arm hanging from the spine, GDQuest's robot)."""
    rotvecs = RNG.normal(scale=0.2, size=(5, len(skeleton.ACTION_JOINTS), 3))
    joints = list(skeleton.ACTION_JOINTS)
    present = set(joints) - {missing}
    kept, folded = gesture.fold_missing(rotvecs, joints, present)
    assert missing not in kept and len(kept) == len(joints) - 1
    from rlanimate_addon.core import kinematics

    full = kinematics.pose_matrices(dict(zip(joints, np.moveaxis(rotvecs, 1, 0), strict=True)))
    merged = kinematics.pose_matrices(dict(zip(kept, np.moveaxis(folded, 1, 0), strict=True)))
    bone = kinematics.bone_index(above)
    assert np.allclose(full[:, bone, :3, :3], merged[:, bone, :3, :3], atol=1e-9)


def test_pointing_hand_curls_the_other_fingers_towards_the_palm():
    from rlanimate_addon.core import kinematics

    for arm in skeleton.ARMS:
        names, rotvecs = gesture.pointing_hand_rotations(arm, 1)
        pose = kinematics.head_positions(kinematics.pose_matrices(dict(zip(names, rotvecs[0], strict=True))))
        rest = kinematics.head_positions(kinematics.pose_matrices({}))
        prefix = skeleton.ARM_PREFIX[arm]
        for finger in ("Middle", "Ring", "Pinky"):
            tip = kinematics.bone_index(f"{prefix}Hand{finger}4")
            assert pose[tip, 2] < rest[tip, 2] - 0.02, f"{arm} {finger} must curl down, towards the palm"


def test_the_pointing_index_is_straight_beyond_the_agents_base_joint():
    names, rotvecs = gesture.pointing_hand_rotations("RIGHT", 2)
    index = [n for n in names if "Index" in n]
    assert index == ["RightHandIndex2", "RightHandIndex3"]
    assert np.all(rotvecs[:, [names.index(n) for n in index]] == 0.0)


def _curled(rest_heads, rest_tails, role, degrees):
    """rest_tails with role's tail turned by `degrees` about the character's forward axis (Y) around its
    head: a bend of a finger that runs sideways along X in the T-pose."""
    turned = dict(rest_tails)
    turn = rotvec_to_matrix(np.array([0.0, np.radians(degrees), 0.0]))
    turned[role] = rest_heads[role] + turn @ np.subtract(rest_tails[role], rest_heads[role])
    return turned


def test_a_finger_whose_last_bone_rests_curled_is_swung_straight_by_its_own_tail():
    rig = gesture.canonical_rig()
    heads, tails = rig.rest_heads, rig.rest_tails
    roles = {r: b for r, b in rig.roles.items() if r != "RightHandIndex4"}
    heads = {r: h for r, h in heads.items() if r in roles}
    last, before = "RightHandIndex3", "RightHandIndex2"
    canonical = np.subtract(skeleton.BONE_BY_NAME["RightHandIndex4"].head, skeleton.BONE_BY_NAME[last].head)
    curled = _curled(heads, tails, last, 25.0)
    swings = gesture.rest_swings(roles, heads, curled, np.eye(3))
    swung = swings[last] @ (curled[last] - heads[last])
    assert np.allclose(swung / np.linalg.norm(swung), canonical / np.linalg.norm(canonical), atol=1e-9)
    assert not np.allclose(swings[last], swings[before], atol=0.1)  # its own turn, not the bone before's
    # a tail that does not follow the finger (an imported rig's bone axis) is not trusted
    crossing = _curled(heads, tails, last, 90.0)
    swings = gesture.rest_swings(roles, heads, crossing, np.eye(3))
    assert np.allclose(swings[last], swings[before])


@pytest.mark.parametrize("request_kwargs, message", [
    (dict(behaviour="POINT", targets=None), "needs a target"),
    (dict(frames=2), "nothing would move. Set a length of at least 3 frames"),
    (dict(frames=1), "at least 3 frames"),
    (dict(frames=0), "at least 3 frames"),
    (dict(behaviour="POINT", targets=np.full((60, 3), np.nan)), r"target's position is not a number .* on 60 of"),
])
def test_bad_requests_raise_before_the_agent_runs(request_kwargs, message):
    agent = ReplayAgent(RNG.uniform(size=(10, spaces.ACTION_SIZE)))
    with pytest.raises(RLAnimateError, match=message):
        gesture.gesture_rotations(agent, _request(**request_kwargs), gesture.canonical_rig())
    assert agent.calls == []


def test_a_rig_needs_only_the_bones_the_gesture_drives_and_names_the_missing_roles():
    agent = ReplayAgent(RNG.uniform(0.3, 0.7, size=(30, spaces.ACTION_SIZE)))
    rig = gesture.canonical_rig()
    optional = {"LeftEye", "RightEye", "Hips", "Spine1"} | {n for n in rig.roles if "Index" in n and n[-1] != "1"} \
        | {n for n in rig.roles if n.startswith("LeftHand") and n != "LeftHand"}
    for name in optional:
        del rig.roles[name]
    targets = np.tile([-1.0, -2.0, 1.6], (30, 1))
    names, _, _ = gesture.gesture_rotations(agent, _request("POINT", "RIGHT", 30, targets=targets), rig)
    assert "Spine1" not in names and "RightHandIndex1" in names
    del rig.roles["Neck"], rig.roles["RightForeArm"]
    with pytest.raises(RLAnimateError, match="roles Neck, RightForeArm"):
        gesture.gesture_rotations(agent, _request(), rig)


def test_an_agent_returning_the_wrong_shape_is_reported():
    agent = ReplayAgent(np.full((60, 44), 0.5))
    with pytest.raises(RLAnimateError, match="shape"):
        gesture.gesture_rotations(agent, _request(), gesture.canonical_rig())


def test_matrix_quat_helpers_agree():
    m = random_rotations(3)
    assert np.allclose(quat_to_matrix(matrix_to_quat(m)), m)


def test_exact_aim_off_keys_the_agents_own_aim():
    """With exact_aim the pointing arm is turned (aim correction); without it the keys are the
    agent's own rotations, and nothing else differs."""
    agent = ReplayAgent(np.random.default_rng(4).uniform(0.3, 0.7, size=(50, spaces.ACTION_SIZE)))
    rig = gesture.canonical_rig()
    targets = np.tile([-1.0, -2.0, 1.6], (50, 1))
    names, aimed, _ = gesture.gesture_rotations(agent, _request("POINT", frames=50, targets=targets), rig)
    raw_names, raw, _ = gesture.gesture_rotations(
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


class TaughtAgent(ReplayAgent):
    """A ReplayAgent of taught target behaviours: AIM_AT declared to point, BECKON declaring nothing."""

    average_frames = {"AIM_AT": 50, "BECKON": 50}
    space = spaces.ObjectiveSpace((Behaviour("AIM_AT", TARGET, AIMS), Behaviour("BECKON", TARGET)))


def test_a_taught_behaviour_of_the_pointing_kind_gets_exact_aim_and_the_pointing_hand():
    """What Point gets comes from what a behaviour does, not its name: AIM_AT, declared to point, keys what Point
    keys from the same actions (the hand shape, the exact aim); BECKON, declaring nothing, gets neither."""
    actions = np.random.default_rng(5).uniform(0.3, 0.7, size=(50, spaces.ACTION_SIZE))
    rig = _animated(gesture.canonical_rig(), 50, scale=0.1)
    targets = np.tile([-1.0, -2.0, 1.6], (50, 1))
    point = gesture.gesture_rotations(ReplayAgent(actions), _request("POINT", frames=50, targets=targets), rig)
    rotations = {(name, exact): gesture.gesture_rotations(
        TaughtAgent(actions), _request(name, frames=50, targets=targets, exact_aim=exact), rig)
        for name in ("AIM_AT", "BECKON") for exact in (True, False)}
    names, quats, under = rotations["AIM_AT", True]
    assert names == point[0] and np.allclose(quats, point[1]) and np.allclose(under, point[2])
    assert "RightHandMiddle2" in names and not np.allclose(quats, rotations["AIM_AT", False][1])
    beckon_names, beckon, _ = rotations["BECKON", True]
    assert not any("HandMiddle" in n for n in beckon_names), "no pointing hand for a behaviour that does not point"
    assert np.array_equal(beckon, rotations["BECKON", False][1]), "no exact aim for it either"


def test_a_nan_start_pose_is_refused_before_anything_is_returned():
    rig = gesture.canonical_rig()
    rig.under[rig.skeleton.index["RightForeArm"], :3, :3] = np.nan
    with pytest.raises(RLAnimateError, match="rotations of RightForeArm are not numbers"):
        gesture.gesture_rotations(ReplayAgent(np.full((60, 45), 0.5)), _request(behaviour="WAVE"), rig)


def test_the_finger_line_runs_through_joints_index_base_to_its_farthest_joint():
    roles = {f"RightHandIndex{k}": f"i{k}" for k in (1, 2, 3)} | {"RightHand": "hand", "RightForeArm": "forearm"}
    assert gesture.finger_line_bones(roles, "RIGHT") == ("i1", "i3", False)
    assert gesture.finger_line_bones(roles | {"RightHandIndex4": "tip"}, "RIGHT") == ("i1", "tip", False)
    assert gesture.finger_line_bones({"RightHandIndex1": "i1", "RightHand": "hand"}, "RIGHT") == ("hand", "i1", False)
    # Without an index finger, the hand's own line: its head (the wrist) to its tail (the hand's end).
    fingerless = {"RightHand": "hand", "RightForeArm": "forearm"}
    assert gesture.finger_line_bones(fingerless, "RIGHT") == ("hand", "hand", True)


def test_over_animation_a_gesture_keys_only_its_arm_and_adds_its_spine_and_head_turn_to_what_plays_underneath():
    """Over the animation alone the spine, neck and head play the gesture's pose at full weight, as on a still
    rig; another gesture's turn of them underneath (`bare` gives the animation without it) stays, so two
    gestures at once both turn them. The other arm is left to the animation."""
    frames = 40
    agent = ReplayAgent(RNG.uniform(0.2, 0.8, size=(frames, spaces.ACTION_SIZE)))
    still = gesture.canonical_rig()
    animated = _animated(still, frames, scale=0.2)
    still_names, still_quats, _ = gesture.gesture_rotations(agent, _request(frames=frames, seed=1), still)
    names, quats, under = gesture.gesture_rotations(agent, _request(frames=frames, seed=1), animated)
    assert set(still_names) - set(names) == {"LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand", "LeftHandIndex1"}
    torso = [skeleton.BONE_NAMES.index(role) for role in gesture.TORSO]
    turned = animated.under.copy()  # another gesture's turn on top of the animation's spine, neck and head
    turned[:, torso, :3, :3] = turned[:, torso, :3, :3] @ rotvec_to_matrix(np.array([0.05, -0.08, 0.03]))
    other = gesture.RigState("Rig", still.skeleton, still.roles, still.family, turned, True,
                             bare={skeleton.BONE_NAMES[i]: animated.under[:, i] for i in torso})
    _, over_other, under_other = gesture.gesture_rotations(agent, _request(frames=frames, seed=1), other)
    full = gesture.blend_weights(frames) == 1.0
    conjugate = np.array([1.0, -1.0, -1.0, -1.0])
    for role in gesture.TORSO:
        k, alone = names.index(role), still_quats[:, still_names.index(role)]
        assert np.allclose(np.abs(np.sum(quats[full, k] * alone[full], axis=-1)), 1.0), "the gesture's own pose"
        kept = quat_multiply(quat_multiply(under_other[:, k], under[:, k] * conjugate), quats[:, k])
        assert np.allclose(np.abs(np.sum(over_other[:, k] * kept, axis=-1)), 1.0), "the other's turn stays"


@pytest.mark.parametrize("animated", [False, True])
def test_a_behaviour_whose_free_arm_has_no_part_holds_it_on_a_still_rig_and_leaves_it_to_the_animation(animated):
    """An agent whose training clips left the free arm still (`still_free_arm`): on a still rig the gesture keys
    that arm's joints on the standing pose it starts from on every frame, whatever the agent's own output for them;
    over animation the gesture does not key that arm at all, held or not (`owned_joints`: it is the animation's).
    The gesturing arm, and other behaviours, play as before."""
    frames = 40
    agent = ReplayAgent(RNG.uniform(0.2, 0.8, size=(frames, spaces.ACTION_SIZE)))
    rig = _animated(gesture.canonical_rig(), frames) if animated else gesture.canonical_rig()
    played_names, played, _ = gesture.gesture_rotations(agent, _request("WAVE", "RIGHT", frames=frames), rig)
    agent.still_free_arm = frozenset({"WAVE"})
    names, held, _ = gesture.gesture_rotations(agent, _request("WAVE", "RIGHT", frames=frames), rig)
    assert names == played_names
    free = gesture.free_arm_columns(names, "RIGHT")
    if animated:
        assert free == [], "over animation the free arm is not keyed"
        np.testing.assert_allclose(held, played)
        return
    assert [names[k] for k in free] == ["LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand", "LeftHandIndex1"]
    start = np.broadcast_to([rotvec_to_quat(gesture.STANDING_POSE.get(names[k], np.zeros(3))) for k in free],
                            (frames, len(free), 4))
    assert np.allclose(np.abs(np.sum(held[:, free] * start, axis=-1)), 1.0)
    assert not np.allclose(np.abs(np.sum(played[:, free] * start, axis=-1)), 1.0), "the agent's own output moves it"
    moving = [k for k in range(len(names)) if k not in free]
    np.testing.assert_allclose(held[:, moving], played[:, moving])
    _, pointed, _ = gesture.gesture_rotations(agent, _request("POINT", frames=frames, targets=[-1.0, -2.0, 1.6]), rig)
    assert not np.allclose(np.abs(np.sum(pointed[:, free] * start, axis=-1)), 1.0), "point is not held"

def test_a_handover_starts_from_the_pose_of_its_first_frame_and_a_resting_bone_from_its_own_basis():
    frames, held = 30, 6
    agent = ReplayAgent(RNG.uniform(0.2, 0.8, size=(frames, spaces.ACTION_SIZE)))
    base = _animated(gesture.canonical_rig(), frames)
    moved = base.under.copy()  # another pose underneath on the held frames but the first
    moved[1:held, :, :3, :3] = rotvec_to_matrix(RNG.normal(scale=0.3, size=(held - 1, len(skeleton.BONES), 3)))
    request = _request(frames=frames, seed=2)
    arm = skeleton.BONE_NAMES.index("RightForeArm")
    results = []
    for under in (base.under, moved):
        rig = gesture.RigState("Rig", base.skeleton, base.roles, base.family, under, True, held=held)
        names, quats, _ = gesture.gesture_rotations(agent, request, rig)
        results.append(quats[:held, names.index("RightForeArm")])
    assert np.allclose(results[0], results[1]), "over the held frames only the first frame's pose counts"
    resting = np.eye(4)
    resting[:3, :3] = rotvec_to_matrix(np.array([0.4, 0.0, 0.0]))
    rig = gesture.RigState("Rig", base.skeleton, base.roles, base.family, base.under, True,
                           resting={"RightForeArm": resting})
    names, quats, _ = gesture.gesture_rotations(agent, request, rig)
    assert np.allclose(np.abs(np.sum(quats[0, names.index("RightForeArm")] * matrix_to_quat(resting[:3, :3]))), 1.0)
    assert not np.allclose(np.abs(np.sum(quats[0, names.index("RightForeArm")]
                                         * matrix_to_quat(base.under[0, arm, :3, :3]))), 1.0)
