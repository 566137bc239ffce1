import numpy as np
import torch

from rlanimate_addon.core import aim, kinematics, skeleton, spaces
from trainer.agent import pointing
from trainer.agent.arm_kinematics import ARMS
from trainer.agent.losses import wrist_error
from trainer.motion import synthesis as gs


def test_the_torch_finger_matches_the_numpy_forward_kinematics():
    rotvecs = np.random.default_rng(0).normal(0.0, 0.5, (6, 15, 3))
    for side, arm in enumerate(skeleton.ARMS):
        base, finger = ARMS.finger(torch.tensor(rotvecs), torch.full((len(rotvecs),), side))
        _, expected_base, expected_finger, _ = aim.finger_lines(rotvecs, arm)
        assert np.allclose(base.numpy(), expected_base, atol=1e-9)
        assert np.allclose(finger.numpy(), expected_finger, atol=1e-9)


def _pointing_clip(arm, target, seed=4):
    clip = gs.synthesise(gs.GestureSpec("POINT", arm, target=target, seed=seed))
    objective = spaces.PAPER_SPACE.make_objective("POINT", arm, spaces.pointing_direction(arm, target), clip.frames)
    return clip, objective


def test_a_clip_is_on_target_exactly_where_it_holds_and_a_turned_arm_misses_by_its_turn():
    arm, target = "RIGHT", (-1.2, -2.5, 1.9)
    clip, objective = _pointing_clip(arm, target)
    rotvecs = clip.action_rotvecs()
    hold = pointing.hold_frames(objective, kinematics.describe(rotvecs))
    first, last = clip.phases["hold"]
    assert hold[first:last + 1].all() and not hold[:5].any() and not hold[-5:].any()
    actions = torch.tensor(spaces.encode_action(rotvecs))
    bounds = torch.tensor(spaces.DEFAULT_ACTION_BOUNDS)
    errors = pointing.pointing_error(actions, torch.tensor(objective), bounds).numpy()
    assert errors[first:last + 1].max() < 1e-8
    turned = rotvecs.copy()
    turned[:, skeleton.ACTION_JOINTS.index("RightArm")] += (0.0, 0.0, 0.05)  # about 3 degrees
    off = pointing.pointing_error(torch.tensor(spaces.encode_action(turned)), torch.tensor(objective), bounds).numpy()
    assert 0.3 * 0.05 ** 2 < np.median(off[first:last + 1]) < 3 * 0.05 ** 2


def test_a_wave_has_no_hold_and_the_error_has_a_gradient():
    objective = spaces.PAPER_SPACE.make_objective("WAVE", "LEFT", 0.5, 20)
    assert not pointing.hold_frames(objective, np.zeros((20, spaces.DESCRIPTION_SIZE))).any()
    _, point = _pointing_clip("LEFT", (1.5, -2.0, 1.0))
    actions = torch.full((len(point), spaces.ACTION_SIZE), 0.5, dtype=torch.float64, requires_grad=True)
    pointing.pointing_error(actions, torch.tensor(point), torch.tensor(spaces.DEFAULT_ACTION_BOUNDS)).sum().backward()
    assert torch.isfinite(actions.grad).all() and actions.grad.abs().sum() > 0


def test_the_wrist_term_is_the_squared_wrist_distance_on_each_frames_own_arm():
    rotvecs = np.random.default_rng(1).normal(0.0, 0.4, (8, 15, 3))
    bounds = torch.tensor(spaces.DEFAULT_ACTION_BOUNDS)
    motion = torch.tensor(spaces.encode_action(rotvecs))
    objective = torch.tensor(
        np.vstack([spaces.PAPER_SPACE.make_objective("WAVE", arm, 0.5, 4) for arm in skeleton.ARMS])
    )
    assert wrist_error(motion, motion, objective, bounds).abs().max() < 1e-12
    turned = rotvecs.copy()
    turned[:, skeleton.ACTION_JOINTS.index("LeftForeArm")] += (0.0, 0.0, 0.2)
    error = wrist_error(torch.tensor(spaces.encode_action(turned)), motion, objective, bounds).numpy()
    wrists = {
        arm: kinematics.head_positions(
            kinematics.pose_matrices(dict(zip(skeleton.ACTION_JOINTS, np.moveaxis(r, 1, 0), strict=True)))
        )[:, kinematics.bone_index(skeleton.ARM_PREFIX[arm] + "Hand")]
        for arm, r in (("LEFT", turned[:4]), ("RIGHT", turned[4:]))
    }
    reference = kinematics.head_positions(kinematics.pose_matrices(dict(zip(skeleton.ACTION_JOINTS, np.moveaxis(
        rotvecs[:4], 1, 0), strict=True))))[:, kinematics.bone_index("LeftHand")]
    assert np.allclose(error[:4], np.sum((wrists["LEFT"] - reference) ** 2, axis=1), atol=1e-9)
    assert error[:4].min() > 1e-3 and error[4:].max() < 1e-12  # the right arm's frames see only the right wrist
