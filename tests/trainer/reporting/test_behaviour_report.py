"""behaviour.{json,md}: methods as rows in each table, every request stored."""
import json

import numpy as np

from rlanimate_addon.core import kinematics, spaces
from trainer.evaluation import baselines, behaviour
from trainer.motion.clip import MotionClip
from trainer.motion.library_plan import plan_library
from trainer.motion.synthesis import synthesise
from trainer.reporting.behaviour_report import write_behaviour
from trainer.reporting.plots import gesture_hand_paths


def _clip(planned):
    spec = planned.spec
    point = spec.behaviour == "POINT"
    return MotionClip(name=planned.file, source=planned.file, fps=30.0, rotvecs=synthesise(spec).action_rotvecs(),
                      behaviour=spec.behaviour, arm=spec.arm, target=spec.target, split=planned.split,
                      attributes=spaces.pointing_direction(spec.arm, spec.target) if point else spec.exaggeration)


class References:
    def get(self, clip):
        descriptions = kinematics.describe(clip.rotvecs)
        return descriptions, spaces.description_joint_positions(descriptions)


def test_report_has_a_row_per_method_in_each_table(tmp_path):
    plan = [p for p in plan_library() if p.spec.arm == "LEFT" and p.spec.behaviour in ("POINT", "WAVE")]
    train = [_clip(p) for p in plan if p.split == "train"][::3]
    test = [_clip(p) for p in plan if p.split == "test"][::2]
    lengths = behaviour.class_lengths(train)
    methods = {
        "no_motion": baselines.NoMotion(baselines.mean_start_pose(train)),
        "nearest_clip": baselines.NearestClip(train),
    }
    sets, clips = {"wave": {}, "point": {}, "point_exact_aim": {}}, {}
    for name, method in methods.items():
        rows = behaviour.request_rows(method, test, References(), kinematics.describe, lengths)
        aimed = behaviour.request_rows(method, [c for c in test if c.behaviour == "POINT"], References(),
                                       kinematics.describe, lengths, exact_aim=True)
        summary = behaviour.summarise(rows)
        sets["wave"][name], sets["point"][name] = summary["wave"], summary["point"]
        sets["point_exact_aim"][name] = behaviour.summarise(aimed)["point"]
        clips[name] = rows
    nearest = methods["nearest_clip"]
    targets = behaviour.random_targets(np.random.default_rng(0), "LEFT", 2)
    report = {"description": "A test report.", "sets": sets, "clips": clips,
              "agent": {"targets_per_arm": 2,
                        "random_targets": {"left": {"own": behaviour.pointing_sweep(nearest, "LEFT", targets, 90,
                                                                                    kinematics.describe),
                                                    "exact": behaviour.pointing_sweep(nearest, "LEFT", targets, 90,
                                                                                      kinematics.describe, True)}},
                        "exaggeration_sweep": {"left": behaviour.exaggeration_sweep(nearest, "LEFT", 100,
                                                                                    kinematics.describe)},
                        "seeded": {"1": behaviour.summarise(clips["nearest_clip"])},
                        "variation": {"seeds": [1, 2], "requests": 2, "deterministic": 2,
                                      "wave": {"median": 0.01, "min": 0.0, "max": 0.02},
                                      "point": {"median": 0.003, "min": 0.002, "max": 0.004}}}}
    write_behaviour(tmp_path, report)
    markdown = (tmp_path / "behaviour.md").read_text()
    for label in ("No motion", "Nearest clip"):
        assert markdown.count(f"| {label} |") == 3  # waves, points, points with exact aim
    assert "0 of 1" in markdown and "1 of 1" in markdown  # waves accepted: the still arm none, the nearest clip its one
    assert markdown.count("\n| 1 | ") == 2, "a seed's row in the seeded waves and in the seeded points"
    assert "waves median 1.0 cm (range 0.0-2.0), points median 0.3 cm" in markdown
    stored = json.loads((tmp_path / "behaviour.json").read_text())
    still_wave = next(r for r in stored["clips"]["no_motion"] if r["behaviour"] == "wave")
    assert still_wave["frequency_ratio"] == 0.0 and still_wave["swing_ratio"] == 0.0
    assert stored["clips"]["nearest_clip"][0]["name"] == test[0].name


class _Still:
    def __init__(self, clip):
        self.pose = clip.rotvecs[0]

    def generate(self, behaviour_name, arm, attributes, frame_count, seed=None):
        return np.repeat(self.pose[None], frame_count, axis=0)


class _Copy:
    def __init__(self, clips):
        self.clips = clips

    def generate(self, behaviour_name, arm, attributes, frame_count, seed=None):
        clip = next(c for c in self.clips if c.behaviour == behaviour_name and np.allclose(c.attributes, attributes))
        return baselines.time_warp(clip.rotvecs, frame_count)


def test_guide_and_raise_tables_sweeps_and_hand_paths(tmp_path):
    plan = [p for p in plan_library() if p.spec.arm == "LEFT" and p.spec.behaviour in ("GUIDE", "RAISE_HAND")]
    clips = [MotionClip(name=p.file, source=p.file, fps=30.0, rotvecs=synthesise(p.spec).action_rotvecs(),
                        behaviour=p.spec.behaviour, arm="LEFT", target=p.spec.target, split=p.split,
                        attributes=(spaces.pointing_direction("LEFT", p.spec.target) if p.spec.target is not None
                                    else p.spec.exaggeration)) for p in plan]
    test = [c for c in clips if c.split == "test"]
    lengths = behaviour.class_lengths(clips)
    methods = {"no_motion": _Still(test[0]), "rlanimate": _Copy(clips)}
    sets, rows = {}, {}
    for name, method in methods.items():
        rows[name] = behaviour.request_rows(method, test, References(), kinematics.describe, lengths)
        for key, summary in behaviour.summarise(rows[name]).items():
            sets.setdefault(key, {})[name] = summary
    empty = {"requests": 0, "score": 0.0, "score_class_length": 0.0, "aligned_score": 0.0, "smoothness": 0.0,
             "elevation_first_error_median": 0.0, "elevation_last_error_median": 0.0,
             "elevation_first_error_max": 0.0, "elevation_last_error_max": 0.0, "swing_ratio_median": 0.0,
             "swing_ratio_min": 0.0, "swing_ratio_max": 0.0, "frequency_ratio_median": 0.0, "cycles_min": 0,
             "cycles_median": 0, "hand_height_ratio_median": 0.0, "accepted_share": 0.0,
             "pointing_angle_median": 0.0, "pointing_angle_max": 0.0, "hold_ratio_median": 0.0}
    sets.update({key: {"rlanimate": empty} for key in ("wave", "point", "point_exact_aim")})
    sweep = behaviour.raise_sweep(_Copy(clips), "LEFT", lengths["RAISE_HAND"], kinematics.describe)
    report = {"description": "A test report.", "sets": sets, "clips": rows,
              "agent": {"targets_per_arm": 2, "random_targets": {}, "exaggeration_sweep": {"left": {
                  "exaggerations": [0.0], "swing": [0.0], "cycles": [0], "swing_rising": False}},
                  "guide_targets": behaviour.guide_sweeps(_Still(test[0]), lengths["GUIDE"], kinematics.describe, 2),
                  "raise_sweep": {"left": sweep}, "seeded": {},
                  "variation": {"seeds": [1, 2], "requests": 0, "deterministic": 0,
                                "wave": {"median": 0.0, "min": 0.0, "max": 0.0},
                                "point": {"median": 0.0, "min": 0.0, "max": 0.0}}}}
    write_behaviour(tmp_path, report)
    markdown = (tmp_path / "behaviour.md").read_text()
    assert '## "This way" (guide), held-out clips (3)' in markdown and "## Raise hand, held-out clips (2)" in markdown
    assert markdown.count("| No motion |") == 2 and "| RLAnimate |" in markdown
    assert "3 of 3 |" in markdown and "2 of 2 |" in markdown and "0 of 3 |" in markdown and "0 of 2 |" in markdown
    assert "| left | 0% |" in markdown  # the still arm guides nowhere
    assert "| 1.00 | yes |" in markdown  # the copied raises rise with the exaggeration: Spearman 1
    panels = [(c.name, "LEFT", {"reference": References().get(c)[1],
                                "still": References().get(MotionClip(c.name, c.name, 30.0, _Still(c).generate(
                                    c.behaviour, "LEFT", None, len(c.rotvecs))))[1]}, behaviour.clip_target(c))
              for c in test]
    gesture_hand_paths(panels, tmp_path / "paths.png")
    assert (tmp_path / "paths.png").stat().st_size > 10_000
