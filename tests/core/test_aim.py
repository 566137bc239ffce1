"""Aim correction: the finger line passes through the target, fades with the phase weight, stays smooth."""
import math

import numpy as np
import pytest

from rlanimate_addon.core import aim, gesture, kinematics, metrics, rotations, runtime, skeleton
from rlanimate_addon.core.easing import minimum_jerk

FRAMES = 120  # about the agent's average Point length
SHORTEST = 46  # 0.4 x that: the shortest length the panel offers


@pytest.fixture(scope="module")
def agent():
    return runtime.load_agent("rlanimate_addon/agents/default.npz")


def random_target(arm, rng):
    """A target 1.5-4 m from the rest shoulder, in the front hemisphere of the arm's side."""
    side = 1.0 if arm == "LEFT" else -1.0
    azimuth = math.radians(rng.uniform(-30.0, 70.0)) * side
    elevation = math.radians(rng.uniform(-25.0, 45.0))
    direction = np.array([math.sin(azimuth) * math.cos(elevation), -math.cos(azimuth) * math.cos(elevation),
                          math.sin(elevation)])
    return skeleton.shoulder_rest_position(arm) + rng.uniform(1.5, 4.0) * direction


def agent_gesture(agent, arm, target, frames=FRAMES):
    objectives = gesture.build_objectives(agent.space, "POINT", arm, frames, targets=np.tile(target, (frames, 1)),
                                          rest_heads=gesture.canonical_rig().rest_heads)
    return gesture.run_agent(agent, "POINT", objectives)  # (N, 15, 3)


def finger_angles(rotvecs, arm, target):
    """(N,) degrees between the finger line and the line from the finger base to the target."""
    _, base, finger, _ = aim.finger_lines(rotvecs, arm)
    to_target = target - base
    cos = np.sum(finger * to_target, axis=1) / np.linalg.norm(to_target, axis=1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def description_positions(rotvecs):
    pose = kinematics.pose_matrices({j: rotvecs[:, i] for i, j in enumerate(skeleton.ACTION_JOINTS)})
    heads = kinematics.head_positions(pose)
    return heads[:, [kinematics.bone_index(bone) for _, bone in skeleton.DESCRIPTION_JOINTS]]  # (N, 10, 3)


@pytest.mark.parametrize("arm", skeleton.ARMS)
def test_full_weight_puts_the_target_on_the_finger_line(agent, arm):
    rng = np.random.default_rng()
    for _ in range(3):
        target = random_target(arm, rng)
        raw = agent_gesture(agent, arm, target)
        aimed = aim.aim_at(raw, arm, target, weights=np.ones(FRAMES))
        assert finger_angles(aimed, arm, target).max() < 0.5
        others = [i for i, j in enumerate(skeleton.ACTION_JOINTS) if j != skeleton.ARM_PREFIX[arm] + "Arm"]
        np.testing.assert_array_equal(aimed[:, others], raw[:, others])


def test_zero_weight_changes_nothing(agent):
    target = random_target("RIGHT", np.random.default_rng())
    raw = agent_gesture(agent, "RIGHT", target)
    np.testing.assert_allclose(aim.aim_at(raw, "RIGHT", target, weights=np.zeros(FRAMES)), raw, atol=1e-9)


@pytest.mark.parametrize("frames", [SHORTEST, FRAMES])
@pytest.mark.parametrize("arm", skeleton.ARMS)
def test_phase_weight_keeps_the_ends_and_smoothness_and_aims_the_apex(agent, arm, frames):
    target = random_target(arm, np.random.default_rng())
    raw = agent_gesture(agent, arm, target, frames)
    aimed = aim.aim_at(raw, arm, target)
    np.testing.assert_allclose(aimed[0], raw[0], atol=1e-9)
    np.testing.assert_allclose(aimed[-1], raw[-1], atol=1e-9)
    _, base, _, _ = aim.finger_lines(aimed, arm)
    apex = int(np.argmax(np.linalg.norm(base - base[0], axis=1)))
    # The corrected apex may fall a frame or two from the raw one, where the weight is just under 1.
    assert finger_angles(aimed, arm, target)[apex] < 2.0
    before, after = metrics.smoothness(description_positions(raw)), metrics.smoothness(description_positions(aimed))
    assert after >= metrics.ARTEFACT_THRESHOLD
    assert after > before - 0.3, f"smoothness fell from {before:.2f} to {after:.2f}"


def test_pointing_phase_rises_to_one_at_the_apex_and_is_zero_at_the_start():
    t = np.linspace(0.0, 1.0, 50)
    base = np.stack([np.sin(np.pi * t) ** 2, np.zeros_like(t), np.zeros_like(t)], axis=1)  # out and back
    weights = aim.pointing_phase(base)
    assert weights[0] == 0.0 and weights[-1] == 0.0
    assert weights[np.argmax(base[:, 0])] == 1.0
    assert np.all((weights >= 0.0) & (weights <= 1.0))


def test_pointing_phase_is_a_minimum_jerk_ramp_in_time_however_the_hand_accelerates():
    frames = np.arange(60)
    out = np.clip(frames / 20.0, 0.0, 1.0) ** 4  # a stroke that starts slowly and ends fast
    back = np.clip((frames - 40) / 20.0, 0.0, 1.0) ** 0.25  # a return that starts fast and ends slowly
    base = np.stack([out - back, np.zeros(60), np.zeros(60)], axis=1)
    weights = aim.pointing_phase(base)
    # First frames at 1% and 50% of the largest distance, (t / 20)^4: 7 and 17; the ramp is stretched
    # back to MIN_RAMP_SHARE of the 60 frames, 12.
    start, full = 5, 17
    expected = minimum_jerk((frames - start) / (full - start))
    np.testing.assert_allclose(weights[:40], expected[:40], atol=1e-12)
    assert weights[-1] == 0.0 and np.all(np.diff(weights[40:]) <= 0.0) and weights[40] == 1.0


def test_a_finger_that_does_not_move_gets_no_correction():
    assert np.all(aim.pointing_phase(np.ones((30, 3))) == 0.0)


def test_shoulder_correction_puts_each_target_exactly_on_its_turned_finger_line():
    rng = np.random.default_rng(11)
    shoulder = rng.normal(scale=0.1, size=(200, 3))
    base = shoulder + rng.normal(scale=0.35, size=(200, 3))
    finger = rng.normal(size=(200, 3))
    finger /= np.linalg.norm(finger, axis=1, keepdims=True)
    directions = rng.normal(size=(200, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    targets = shoulder + directions * rng.uniform(1.5, 4.0, (200, 1))  # 1.5-4 m away
    turn = rotations.rotvec_to_matrix(aim.shoulder_corrections(shoulder, base, finger, targets))  # (200, 3, 3)
    turned_base = shoulder + np.einsum("nij,nj->ni", turn, base - shoulder)
    turned_finger = np.einsum("nij,nj->ni", turn, finger)
    to_target = targets - turned_base
    cos = np.sum(to_target * turned_finger, axis=1) / np.linalg.norm(to_target, axis=1)
    assert np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).max() < 1e-5, "the target must lie ahead on the line"
