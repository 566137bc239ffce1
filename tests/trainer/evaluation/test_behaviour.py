"""Behaviour evaluation (trainer.evaluation.behaviour) on synthesised library clips, with the numpy FK:
a copy passes, a still arm and a class mean are told apart from it."""
import numpy as np
import pytest

from rlanimate_addon.core import kinematics, spaces
from trainer.evaluation import baselines, behaviour
from trainer.motion.clip import MotionClip
from trainer.motion.library_plan import plan_library
from trainer.motion.synthesis import synthesise


def _clip(planned):
    spec = planned.spec
    point = spec.behaviour == "POINT"
    return MotionClip(name=planned.file, source=planned.file, fps=30.0,
                      rotvecs=synthesise(spec).action_rotvecs(), behaviour=spec.behaviour, arm=spec.arm,
                      attributes=spaces.pointing_direction(spec.arm, spec.target) if point else spec.exaggeration,
                      target=spec.target, exaggeration=spec.exaggeration, split=planned.split)


@pytest.fixture(scope="module")
def library():
    """The right arm's training and held-out clips of the sample library, synthesised in numpy."""
    plan = [p for p in plan_library() if p.spec.arm == "RIGHT" and p.spec.behaviour in ("POINT", "WAVE")]
    train = [_clip(p) for p in plan if p.split == "train"]
    test = [_clip(p) for p in plan if p.split == "test"]
    return train, test


class NumpyReferences:
    def get(self, clip):
        descriptions = kinematics.describe(clip.rotvecs)
        return descriptions, spaces.description_joint_positions(descriptions)


class Copy:
    """Answers each held-out request with its own clip, time-warped to the requested length."""

    def __init__(self, clips):
        self.clips = clips

    def generate(self, behaviour_name, arm, attributes, frame_count, seed=None):
        clip = next(c for c in self.clips if c.behaviour == behaviour_name and c.arm == arm
                    and np.allclose(c.attributes, attributes))
        return baselines.time_warp(clip.rotvecs, frame_count)


def test_copy_passes_and_still_arm_and_class_mean_do_not(library):
    train, test = library
    lengths = behaviour.class_lengths(train)
    results = {}
    for name, method in (("copy", Copy(test)), ("no_motion", baselines.NoMotion(baselines.mean_start_pose(train))),
                         ("class_mean", baselines.ClassMean(train))):
        rows = behaviour.request_rows(method, test, NumpyReferences(), kinematics.describe, lengths)
        results[name] = behaviour.summarise(rows)
    copy, still, mean = results["copy"], results["no_motion"], results["class_mean"]
    assert copy["wave"]["accepted_share"] == 1.0 and copy["wave"]["score"] == pytest.approx(100.0)
    assert copy["point"]["pointing_angle_max"] < 0.01
    assert copy["point"]["elevation_first_error_max"] == pytest.approx(0.0, abs=1e-9)
    assert still["wave"]["accepted_share"] == 0.0 and still["wave"]["swing_ratio_max"] < 0.1
    assert still["point"]["pointing_angle_median"] > 45.0
    assert mean["wave"]["accepted_share"] == 0.0 and mean["wave"]["swing_ratio_median"] < 0.75
    assert mean["wave"]["score"] > 99.0, "the paper's score cannot tell a class mean from a wave"
    assert mean["point"]["pointing_angle_median"] > 10.0


def test_exact_aim_makes_any_pointing_method_hit(library):
    train, test = library
    points = [c for c in test if c.behaviour == "POINT"]
    lengths = behaviour.class_lengths(train)
    nearest = baselines.NearestClip(train)
    raw = behaviour.request_rows(nearest, points, NumpyReferences(), kinematics.describe, lengths)
    aimed = behaviour.request_rows(nearest, points, NumpyReferences(), kinematics.describe, lengths, exact_aim=True)
    assert max(r["pointing_angle"] for r in aimed) < 0.5 < max(r["pointing_angle"] for r in raw)


def test_random_targets_lie_in_the_library_ranges():
    targets = behaviour.random_targets(np.random.default_rng(0), "LEFT", 200)
    shoulder = np.array([0.17, 0.0, 1.45])
    distance = np.linalg.norm(targets - shoulder, axis=1)
    assert targets.shape == (200, 3) and np.all((distance >= 1.5) & (distance <= 4.0))
    assert np.all(targets[:, 2] >= behaviour.LOWEST_TARGET_M)
    assert np.mean(targets[:, 1] < 0.0) > 0.9  # in front but for the ones far out to the side


def test_sweeps_and_seed_variation_on_a_seeded_method(library):
    train, test = library

    class Seeded:
        """The class mean, with a seed shifting the whole clip in time: seeds differ, no seed repeats."""

        def __init__(self):
            self.mean = baselines.ClassMean(train)

        def generate(self, behaviour_name, arm, attributes, frame_count, seed=None):
            clip = self.mean.generate(behaviour_name, arm, attributes, frame_count)
            return clip if seed is None else np.roll(clip, 3 * seed, axis=0)

    rows = behaviour.seed_variation(Seeded(), test[:2], kinematics.describe, seeds=(1, 2))
    assert all(r["deterministic"] and r["variation"] > 0.0 for r in rows)
    assert [r["behaviour"] for r in rows] == [c.behaviour.lower() for c in test[:2]]
    lengths = behaviour.class_lengths(train)
    plain, shifted = (behaviour.request_rows(Seeded(), test[:2], NumpyReferences(), kinematics.describe, lengths,
                                             seed=seed) for seed in (None, 2))
    assert all(s["score"] < p["score"] for p, s in zip(plain, shifted, strict=True)), (
        "a seed's answer is the one scored"
    )
    sweep = behaviour.exaggeration_sweep(baselines.NearestClip(train), "RIGHT", 100, kinematics.describe)
    assert sweep["swing_rising"] and len(sweep["swing"]) == len(behaviour.EXAGGERATIONS)
    targets = behaviour.random_targets(np.random.default_rng(1), "RIGHT", 3)
    aimed = behaviour.pointing_sweep(baselines.NearestClip(train), "RIGHT", targets, 100, kinematics.describe,
                                     exact_aim=True)
    assert aimed["max_angle"] < 0.5 and len(aimed["angles"]) == 3


def _new_behaviour_clips(arm):
    """(train, test) guide and raise-hand clips of one arm, synthesised in numpy, labelled as the manifest does."""
    plan = [p for p in plan_library() if p.spec.arm == arm and p.spec.behaviour in ("GUIDE", "RAISE_HAND")]
    clips = [MotionClip(name=p.file, source=p.file, fps=30.0, rotvecs=synthesise(p.spec).action_rotvecs(),
                        behaviour=p.spec.behaviour, arm=arm, target=p.spec.target, exaggeration=p.spec.exaggeration,
                        attributes=(spaces.pointing_direction(arm, p.spec.target) if p.spec.target is not None
                                    else p.spec.exaggeration), split=p.split) for p in plan]
    return [c for c in clips if c.split == "train"], [c for c in clips if c.split == "test"]


class Still:
    """The first frame of a clip held for the whole request."""

    def __init__(self, clip):
        self.pose = clip.rotvecs[0]

    def generate(self, behaviour_name, arm, attributes, frame_count, seed=None):
        return np.repeat(self.pose[None], frame_count, axis=0)


def test_guide_and_raise_rows_summaries_and_sweeps_pass_a_copy_and_fail_a_still_arm():
    train, test = _new_behaviour_clips("LEFT")
    lengths = behaviour.class_lengths(train)
    copy, still = (behaviour.summarise(behaviour.request_rows(method, test, NumpyReferences(), kinematics.describe,
                                                              lengths)) for method in (Copy(test), Still(test[0])))
    assert copy["guide"]["accepted_share"] == 1.0 and copy["guide"]["heading_error_max"] < 3.0
    assert copy["raise_hand"]["accepted_share"] == 1.0 and copy["raise_hand"]["height_error_max"] < 1e-9
    assert still["guide"]["accepted_share"] == 0.0 and still["guide"]["palm_up_median"] > 80.0
    assert still["raise_hand"]["accepted_share"] == 0.0
    guides = behaviour.guide_sweeps(Still(test[0]), lengths["GUIDE"], kinematics.describe, count=3)
    assert set(guides) == {"left", "right"} and guides["right"]["accepted_share"] == 0.0
    assert guides["left"]["palm_up_median"] > 80.0 and guides["left"]["reach_median"] < 0.3
    raised = behaviour.raise_sweep(Copy(train + test), "LEFT", lengths["RAISE_HAND"], kinematics.describe)
    assert raised["height_rising"] and raised["spearman"] == pytest.approx(1.0) and max(raised["strokes"]) <= 3
    flat = behaviour.raise_sweep(Still(train[-1]), "LEFT", 100, kinematics.describe)
    assert not flat["height_rising"] and np.isnan(flat["spearman"])
