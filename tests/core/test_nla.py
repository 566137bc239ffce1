"""Blender's NLA timing and blending in numpy (core/nla.py) and the bone constraints beside it
(core/bone_constraints.py); tests/addon/test_pose_underneath.py holds them to Blender's own evaluation."""
import numpy as np

from rlanimate_addon.core import bone_constraints, nla
from rlanimate_addon.core.rotations import quat_to_matrix, rotvec_to_quat

FRAMES = np.arange(0.0, 41.0)


def test_a_track_plays_the_strip_a_frame_falls_in_and_holds_as_blender_does():
    first = nla.Strip(5, 10, 1, 6, extrapolation="HOLD")
    second = nla.Strip(20, 25, 1, 6, extrapolation="HOLD_FORWARD")
    third = nla.Strip(30, 33, 1, 4, extrapolation="NOTHING")
    index, at = nla.playing([first, second, third], FRAMES)
    assert (index[:5] == 0).all() and (at[:5] == 5).all(), "the first strip, HOLD, holds its start before it"
    assert (index[11:20] == 0).all() and (at[11:20] == 10).all(), "until the next strip, the one before holds its end"
    assert (index[26:30] == 1).all() and (at[26:30] == 25).all(), "HOLD_FORWARD holds after"
    assert (index[34:] == -1).all(), "nothing after the last strip with NOTHING"
    forward_first = nla.Strip(5, 10, 1, 6, extrapolation="HOLD_FORWARD")
    assert (nla.playing([forward_first], FRAMES)[0][:5] == -1).all(), "HOLD_FORWARD does not hold before"
    muted = nla.Strip(5, 10, 1, 6, muted=True)
    assert (nla.playing([muted], FRAMES)[0] == -1).all()


def test_the_action_time_of_scaled_and_repeated_strips():
    strip = nla.Strip(10, 30, 1, 11, scale=1.0, repeat=2.0)
    times = nla.strip_time(strip, np.array([10.0, 15.0, 20.0, 25.0, 30.0]))
    assert np.allclose(times, [1, 6, 1, 6, 11]), "the end of a whole repeat plays the action's end, not its start"
    slow = nla.Strip(0, 20, 0, 10, scale=2.0)
    assert np.allclose(nla.strip_time(slow, np.array([0.0, 5.0, 19.0])), [0.0, 2.5, 9.5])


def test_influence_ramps_over_the_blends_and_a_fixed_one_holds():
    strip = nla.Strip(0, 20, 0, 20, blend_in=4, blend_out=10)
    assert np.allclose(nla.influence(strip, np.array([0.0, 2.0, 4.0, 8.0, 15.0, 20.0])), [0, 0.5, 1, 1, 0.5, 0])
    assert np.allclose(nla.influence(nla.Strip(0, 5, 0, 5, influence=0.4), np.arange(3.0)), 0.4)


def test_replace_mixes_and_combine_adds_multiplies_and_turns():
    weight = np.array([0.0, 0.5, 1.0])
    keyed = np.array([True, False, True])
    lower, value = np.tile([1.0, 2.0, 3.0], (3, 1)), np.tile([3.0, 5.0, 7.0], (3, 1))
    replaced = nla.blend("REPLACE", "location", lower, value, weight, keyed)
    assert np.allclose(replaced, [[1, 2, 3], [2, 2, 5], [3, 2, 7]]), "unkeyed components keep what is below"
    assert np.allclose(nla.blend("COMBINE", "location", lower, value, weight, keyed), [[1, 2, 3], [2.5, 2, 6.5],
                                                                                       [4, 2, 10]])
    assert np.allclose(nla.blend("COMBINE", "scale", lower, value, weight, keyed)[2], [3, 2, 21])
    below, turn = rotvec_to_quat([0.0, 0.0, 0.4]), rotvec_to_quat([0.3, 0.0, 0.0])
    combined = nla.blend("COMBINE", "rotation_quaternion", np.tile(below, (3, 1)), np.tile(turn, (3, 1)), weight,
                         np.ones(4, dtype=bool))
    assert np.allclose(combined[0], below), "no influence, no turn"
    halfway = quat_to_matrix(below) @ quat_to_matrix(rotvec_to_quat([0.15, 0.0, 0.0]))
    assert np.allclose(quat_to_matrix(combined[1]), halfway, atol=1e-6)
    assert np.allclose(quat_to_matrix(combined[2]), quat_to_matrix(below) @ quat_to_matrix(turn), atol=1e-6)


def test_a_combined_turn_too_small_for_single_precision_plays_as_none_as_in_blender():
    tiny = rotvec_to_quat([2e-5, 0.0, 0.0])[None]
    combined = nla.blend("COMBINE", "rotation_quaternion", np.array([[1.0, 0.0, 0.0, 0.0]]), tiny, np.ones(1),
                         np.ones(4, dtype=bool))
    assert np.array_equal(combined, [[1.0, 0.0, 0.0, 0.0]])
    assert not nla.combinable("rotation_quaternion", np.array([True, True, False, True]))
    assert not nla.combinable("rotation_axis_angle", np.ones(4, dtype=bool))


def test_copies_and_their_interpolation_by_influence():
    owner, target = np.tile(np.eye(4), (2, 1, 1)), np.tile(np.eye(4), (2, 1, 1))
    owner[:, :3, :3] *= 2.0
    owner[:, :3, 3] = [1.0, 0.0, 0.0]
    target[:, :3, :3] = quat_to_matrix(rotvec_to_quat([0.0, 0.0, np.pi / 2]))
    target[:, :3, 3] = [0.0, 3.0, 0.0]
    rotated = bone_constraints.copy("COPY_ROTATION", owner, target)
    assert np.allclose(rotated[:, :3, :3], 2.0 * target[:, :3, :3]) and np.allclose(rotated[:, :3, 3], [1, 0, 0])
    assert np.allclose(bone_constraints.copy("COPY_LOCATION", owner, target)[:, :3, 3], [0, 3, 0])
    assert np.array_equal(bone_constraints.copy("COPY_TRANSFORMS", owner, target), target)
    half = bone_constraints.interpolate(owner, target, 0.5)
    assert np.allclose(half[:, :3, 3], [0.5, 1.5, 0.0])
    expected = quat_to_matrix(rotvec_to_quat([0.0, 0.0, np.pi / 4])) * 1.5  # the turn slerped, the scale mixed
    assert np.allclose(half[:, :3, :3], expected)
    assert np.allclose(bone_constraints.interpolate(owner, target, 0.0), owner)
    mirrored = np.array(owner)
    mirrored[:, 0, 0] = -2.0
    assert bone_constraints.unsupported(mirrored) and not bone_constraints.unsupported(owner)
    sheared, rounded = np.array(owner), np.array(owner)
    sheared[:, 0, 1] = 0.01
    rounded[:, :3, :3] += 1e-6 * np.array([[0.5, -1.0, 0.3], [0.8, 0.2, -0.6], [-0.4, 0.9, 0.1]])  # single precision
    assert bone_constraints.unsupported(sheared) and not bone_constraints.unsupported(rounded)
