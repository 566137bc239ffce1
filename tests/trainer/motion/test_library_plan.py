import json
from collections import Counter

import numpy as np
import pytest

from rlanimate_addon.core import skeleton, spaces
from trainer.motion import library_plan
from trainer.motion.synthesis import synthesise
from trainer.paths import CLIP_DIR, DEFAULT_MANIFEST


@pytest.fixture(scope="module")
def plan():
    return library_plan.plan_library()


def test_plan_has_the_papers_hundred_clips_and_split_then_guides_and_raised_hands(plan):
    assert len(plan) == 200 and len({p.file for p in plan}) == 200
    counts = Counter((p.spec.behaviour, p.spec.arm) for p in plan)
    assert set(counts.values()) == {25} and len(counts) == 8
    tests = Counter((p.spec.behaviour, p.spec.arm) for p in plan if p.split == "test")
    assert tests == {("POINT", "LEFT"): 3, ("POINT", "RIGHT"): 3, ("WAVE", "LEFT"): 2, ("WAVE", "RIGHT"): 2,
                     ("GUIDE", "LEFT"): 3, ("GUIDE", "RIGHT"): 3, ("RAISE_HAND", "LEFT"): 2, ("RAISE_HAND", "RIGHT"): 2}
    assert [p.spec.behaviour for p in plan[:100]] == ["POINT"] * 50 + ["WAVE"] * 50  # the paper's clips come first


def _targets(plan, behaviour, arm, farthest):
    """The planned clips of a target behaviour on `arm`, and their unit directions from the rest shoulder;
    asserts the targets lie 1.5 m to `farthest` away."""
    clips = [p for p in plan if p.spec.behaviour == behaviour and p.spec.arm == arm]
    offsets = np.array([p.spec.target for p in clips]) - skeleton.shoulder_rest_position(arm)
    distance = np.linalg.norm(offsets, axis=1)
    assert np.all((distance >= 1.5 - 1e-3) & (distance <= farthest + 1e-3))
    return clips, offsets / distance[:, None]


def test_guide_targets_lie_ahead_and_to_the_side_and_raises_use_the_wave_grid(plan):
    for arm in skeleton.ARMS:
        sign = 1.0 if arm == "LEFT" else -1.0
        _, direction = _targets(plan, "GUIDE", arm, farthest=5.0)
        assert np.all(direction[:, 2] < np.sin(np.radians(12.5))) and direction[:, 2].min() < -0.4
        assert (sign * direction[:, 0]).min() < -0.3 and (sign * direction[:, 0]).max() > 0.8
        raises = [p for p in plan if p.spec.behaviour == "RAISE_HAND" and p.spec.arm == arm]
        waves = [p for p in plan if p.spec.behaviour == "WAVE" and p.spec.arm == arm]
        assert [p.spec.exaggeration for p in raises] == [p.spec.exaggeration for p in waves]
        assert [p.split for p in raises] == [p.split for p in waves]


def test_test_waves_use_exaggerations_no_training_clip_has(plan):
    train = {p.spec.exaggeration for p in plan if p.split == "train" and p.spec.behaviour == "WAVE"}
    test = [p.spec.exaggeration for p in plan if p.split == "test" and p.spec.behaviour == "WAVE"]
    assert not set(test) & train
    assert all(0.0 < e < 1.0 for e in test)  # inside the trained range, not extrapolation
    for arm in skeleton.ARMS:
        values = sorted(p.spec.exaggeration for p in plan if p.spec.behaviour == "WAVE" and p.spec.arm == arm)
        assert values[0] <= 0.02 and values[-1] >= 0.98 and np.max(np.diff(values)) < 0.05


def test_point_targets_cover_the_front_hemisphere_at_1_5_to_4_m(plan):
    for arm in skeleton.ARMS:
        sign = 1.0 if arm == "LEFT" else -1.0
        points, direction = _targets(plan, "POINT", arm, farthest=4.0)
        assert np.all(np.array([p.spec.target for p in points])[:, 2] >= library_plan.LOWEST_TARGET - 1e-9)
        assert np.all(direction[:, 1] < 0.1)  # in front (or beside), never behind
        assert direction[:, 2].max() > 0.6 and direction[:, 2].min() < -0.4  # high and low
        assert (sign * direction[:, 0]).min() < -0.6 and (sign * direction[:, 0]).max() > 0.8  # across, out
        # Held-out targets lie inside the spread of the training targets.
        test = [p for p in points if p.split == "test"]
        train_dirs = direction[[p.split == "train" for p in points]]
        for p in test:
            d = spaces.pointing_direction(arm, p.spec.target)
            nearest = np.degrees(np.arccos(np.clip(train_dirs @ d, -1, 1))).min()
            assert 3.0 < nearest < 35.0


def test_plan_is_deterministic_in_its_seed(plan):
    assert library_plan.plan_library() == plan
    assert library_plan.plan_library(seed=7) != plan


def test_every_planned_clip_stays_inside_the_action_bounds(plan):
    low, high = spaces.DEFAULT_ACTION_BOUNDS[:, 0], spaces.DEFAULT_ACTION_BOUNDS[:, 1]
    for planned in plan:
        clip = synthesise(planned.spec)
        flat = clip.action_rotvecs().reshape(clip.frames, -1)
        assert np.all(flat >= low) and np.all(flat <= high), planned.file
        assert 2.5 <= clip.frames / clip.fps <= 4.5


def test_committed_manifest_matches_the_plan_and_the_files(plan):
    manifest = json.loads(DEFAULT_MANIFEST.read_text())
    assert manifest["fps"] == 30 and manifest["rig"] == "../character.fbx"
    entries = {e["file"]: e for e in manifest["clips"]}
    assert list(entries) == [p.file for p in plan]
    total = 0
    for planned in plan:
        entry, spec = entries[planned.file], planned.spec
        path = CLIP_DIR / planned.file
        assert path.is_file()
        total += path.stat().st_size
        assert (entry["behaviour"], entry["arm"], entry["split"], entry["fps"]) == (
            spec.behaviour, spec.arm, planned.split, 30)
        if spec.behaviour in ("POINT", "GUIDE"):
            assert entry["exaggeration"] is None and entry["target"] == list(spec.target)
            np.testing.assert_allclose(entry["direction"], spaces.pointing_direction(spec.arm, spec.target), atol=1e-6)
        else:
            assert entry["target"] is None and entry["direction"] is None and entry["exaggeration"] == spec.exaggeration
    assert total < 40e6
    # Frame counts are those the generator makes (checked on a few, for speed).
    for planned in plan[::17]:
        assert entries[planned.file]["frames"] == synthesise(planned.spec).frames
