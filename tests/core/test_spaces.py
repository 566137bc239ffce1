import numpy as np
import pytest

from rlanimate_addon.core import behaviours, skeleton, spaces
from rlanimate_addon.core.behaviours import INTENSITY, TARGET, Behaviour
from rlanimate_addon.core.errors import RLAnimateError


def test_sizes_match_the_paper_tables():
    assert spaces.PAPER_SPACE.size == 7
    assert spaces.DESCRIPTION_SIZE == 42
    assert spaces.ACTION_SIZE == 45
    assert spaces.DEFAULT_ACTION_BOUNDS.shape == (45, 2)
    assert np.all(spaces.DEFAULT_ACTION_BOUNDS[:, 0] < spaces.DEFAULT_ACTION_BOUNDS[:, 1])


def test_action_round_trip_inside_bounds():
    rng = np.random.default_rng(0)
    low, high = spaces.DEFAULT_ACTION_BOUNDS.T
    rotvecs = rng.uniform(low, high).reshape(15, 3)
    batch = np.stack([rotvecs, rotvecs * 0.5])  # (2, 15, 3)
    actions = spaces.encode_action(batch)
    assert actions.shape == (2, 45)
    assert np.all((actions >= 0) & (actions <= 1))
    np.testing.assert_allclose(spaces.decode_action(actions), batch, atol=1e-12)


def test_action_encoding_clips_to_bounds():
    too_far = np.full((15, 3), 10.0)
    np.testing.assert_array_equal(spaces.encode_action(too_far), np.ones(45))


def test_point_objective_layout():
    objective = spaces.PAPER_SPACE.make_objective("POINT", "RIGHT", [0.0, -2.0, 0.0], 4)
    assert objective.shape == (4, 7)
    np.testing.assert_array_equal(objective[:, 0], 1.0)
    np.testing.assert_array_equal(objective[:, 1:3], [[0.0, 1.0]] * 4)
    np.testing.assert_allclose(objective[:, 3:6], [[0.0, -1.0, 0.0]] * 4)
    np.testing.assert_allclose(objective[:, 6], [0.0, 1 / 3, 2 / 3, 1.0])


def test_wave_objective_repeats_exaggeration():
    objective = spaces.PAPER_SPACE.make_objective("WAVE", "LEFT", 0.25, 3)
    np.testing.assert_array_equal(objective[:, 0], 2.0)
    np.testing.assert_array_equal(objective[:, 1:3], [[1.0, 0.0]] * 3)
    np.testing.assert_array_equal(objective[:, 3:6], 0.25)


@pytest.mark.parametrize("args, fragment", [
    (("WAVE", "LEFT", 1.5, 10), "between 0 and 1"),
    (("POINT", "LEFT", [0, 0, 0], 10), "zero"),
    (("POINT", "LEFT", [np.nan, 0, 1], 10), "not a number"),
    (("POINT", "LEFT", [1, 0, 0], 0), "at least 2 frames"),
    (("JUMP", "LEFT", 0.5, 10), "Unknown behaviour"),
    (("WAVE", "MIDDLE", 0.5, 10), "Unknown arm"),
])
def test_bad_objectives_name_the_problem(args, fragment):
    with pytest.raises(RLAnimateError, match=fragment):
        spaces.PAPER_SPACE.make_objective(*args)


def test_pointing_direction_starts_at_the_rest_shoulder():
    shoulder = skeleton.shoulder_rest_position("LEFT")
    target = shoulder + np.array([0.0, -3.0, 0.0])
    np.testing.assert_allclose(spaces.pointing_direction("LEFT", target), [0.0, -1.0, 0.0])
    with pytest.raises(RLAnimateError):
        spaces.pointing_direction("LEFT", shoulder)


def test_describe_layout_and_unit_effectors():
    positions = {bone: np.array([i, 2.0 * i, 3.0 * i]) for i, (_, bone) in enumerate(skeleton.DESCRIPTION_JOINTS)}
    positions["LeftHandIndex4"] = positions["LeftHandIndex1"] + [0.0, 0.0, 2.0]
    positions["RightHandIndex4"] = positions["RightHandIndex1"] + [3.0, 0.0, 0.0]
    eyes = {"LeftEye": np.array([0.0, -2.0, 0.0]), "RightEye": np.array([0.0, -1.0, 0.0])}
    d = spaces.describe(positions, eyes)
    assert d.shape == (42,)
    np.testing.assert_allclose(d[0:12], [0, -1, 0, 0, -1, 0, 0, 0, 1, 1, 0, 0])
    joints = spaces.description_joint_positions(d)
    np.testing.assert_allclose(joints[4], [4.0, 8.0, 12.0])  # left elbow, the fifth joint


def _four():
    return spaces.ObjectiveSpace(behaviours.ordered([*behaviours.PAPER, Behaviour("THIS_WAY", TARGET),
                                                     Behaviour("RAISE_HAND", INTENSITY)]))


def test_more_than_two_behaviours_get_a_one_hot_label_before_the_same_fields():
    space = _four()
    assert space.names == ("POINT", "WAVE", "RAISE_HAND", "THIS_WAY") and space.size == 4 + 6
    guide = space.make_objective("THIS_WAY", "LEFT", [0.0, -2.0, 0.0], 3)
    raise_hand = space.make_objective("RAISE_HAND", "RIGHT", 0.75, 3)
    np.testing.assert_array_equal(guide[:, :4], [[0, 0, 0, 1]] * 3)
    np.testing.assert_array_equal(raise_hand[:, :4], [[0, 0, 1, 0]] * 3)
    for objective, arm in ((guide, [1.0, 0.0]), (raise_hand, [0.0, 1.0])):
        np.testing.assert_array_equal(objective[:, spaces.OBJECTIVE_ARM], [arm] * 3)
        np.testing.assert_array_equal(objective[:, spaces.OBJECTIVE_TIME], [0.0, 0.5, 1.0])
    np.testing.assert_allclose(guide[:, spaces.OBJECTIVE_ATTRIBUTES], [[0.0, -1.0, 0.0]] * 3)
    np.testing.assert_array_equal(raise_hand[:, spaces.OBJECTIVE_ATTRIBUTES], 0.75)
    # the paper's pair lays out exactly as Table 2, whatever the fields are addressed by
    paper = spaces.PAPER_SPACE.make_objective("WAVE", "LEFT", 0.5, 2)
    np.testing.assert_array_equal(paper, [[2.0, 1.0, 0.0, 0.5, 0.5, 0.5, 0.0], [2.0, 1.0, 0.0, 0.5, 0.5, 0.5, 1.0]])


def test_labels_tell_the_behaviour_and_kind_and_refuse_a_label_of_none():
    space = _four()
    objectives = np.concatenate([space.make_objective("THIS_WAY", "LEFT", [1.0, 0.0, 0.0], 2),
                                 space.make_objective("WAVE", "LEFT", 0.2, 3)])
    assert space.behaviours_in(objectives) == {"THIS_WAY", "WAVE"}
    assert space.kind_mask(objectives, TARGET).tolist() == [True, True, False, False, False]
    assert space.label_mask(objectives, "WAVE").tolist() == [False, False, True, True, True]
    assert space.kind("RAISE_HAND") == INTENSITY and space.of_kind(TARGET) == ("POINT", "THIS_WAY")
    objectives[0, :4] = (0.0, 1.0, 0.0, 1.0)
    with pytest.raises(RLAnimateError, match="label that is none of"):
        space.behaviours_in(objectives)
    with pytest.raises(RLAnimateError, match=r"Only an oscillating behaviour \(a wave\) carries a rhythm"):
        space.make_objective("RAISE_HAND", "LEFT", 0.5, 2, rhythm=np.zeros((2, 2)))
    with pytest.raises(RLAnimateError, match="Unknown behaviour 'BECKON'"):
        space.make_objective("BECKON", "LEFT", 0.5, 2)
