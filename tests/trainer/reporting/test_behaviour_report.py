"""behaviour.{json,md}: methods as rows in each table, every request stored."""
import json

import numpy as np

from rlanimate_addon.core import kinematics, spaces
from trainer.evaluation import baselines, behaviour
from trainer.motion.clip import MotionClip
from trainer.motion.library_plan import plan_library
from trainer.motion.synthesis import synthesise
from trainer.reporting.behaviour_report import write_behaviour


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
    methods = {"no_motion": baselines.NoMotion(baselines.mean_start_pose(train)), "nearest_clip": baselines.NearestClip(train)}
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
