"""The guide and goodbye experiment on real capture: its style split, what trains, and the labels on import."""
from types import SimpleNamespace

import numpy as np
import pytest

from rlanimate_addon.core import behaviours, skeleton
from trainer.experiments import realmocap
from trainer.experiments.realmocap_gestures import BYE, GUIDE, gesture_sets
from trainer.motion import realmocap_takes
from trainer.motion.realmocap_takes import GESTURE_LABELS, GESTURE_STYLES, WITHHELD_TAKES
from trainer.paths import REALMOCAP_DIR

needs_data = pytest.mark.skipif(not (REALMOCAP_DIR / "wave").is_dir(),
                                reason=f"real motion capture not found at {REALMOCAP_DIR} "
                                       "(../shared/realmocap/ beside the repository)")


def _takes(names):
    """Stand-ins of the experiment's clips from file names alone: content, style, take and behaviour."""
    takes = []
    for name in names:
        info = realmocap_takes.parse_name(name)
        takes.append(SimpleNamespace(**info, name=name, behaviour=GESTURE_LABELS[info["content"]].name))
    return takes


def test_held_out_styles_are_a_seeded_draw_shared_by_guide_and_bye():
    held_out = realmocap_takes.gesture_test_styles()
    assert held_out == realmocap_takes.gesture_test_styles(realmocap_takes.GESTURE_SPLIT_SEED)
    assert len(held_out) == realmocap_takes.GESTURE_TEST_COUNT == 4 and set(held_out) <= set(GESTURE_STYLES)
    assert realmocap_takes.gesture_test_styles(seed=1) != held_out  # the seed, not a fixed list, chooses
    takes = _takes([f"dataset-1_{content}_{style}_001.bvh" for content in ("guide", "bye") for style in GESTURE_STYLES]
                   + ["dataset-2_wave-left-hand_normal_001.bvh"])
    train, test = realmocap_takes.gesture_split(takes)
    for content in ("guide", "bye"):
        assert sorted(c.style for c in test if c.content == content) == list(held_out)
        assert len([c for c in train if c.content == content]) == 10
    assert not {c.style for c in train} & set(held_out)
    assert all(c.content != "wave" for c in train + test)


@needs_data
def test_no_held_out_style_and_no_take_011_to_020_enters_training():
    names = [path.name for folder in ("wave", "bye", "guide")
             for path in realmocap_takes.take_paths(REALMOCAP_DIR / folder)]
    takes = _takes(names)
    by_content = {content: [t for t in takes if t.content == content] for content in ("wave", "bye", "guide")}
    train, sets = gesture_sets(by_content["wave"], by_content["bye"], by_content["guide"])
    held_out = set(realmocap_takes.gesture_test_styles())
    every = train + [t for clips in sets.values() for t in clips]
    assert not any(t.take in WITHHELD_TAKES for t in every)
    assert not any(t.style in held_out for t in train if t.content != "wave")
    assert {t.take for t in sets["waves"]} == {"009", "010"}
    assert not {t.name for t in train} & {t.name for key in ("waves", "guide_test", "bye_test") for t in sets[key]}
    counts = {b: sum(t.behaviour == b for t in train) for b in (behaviours.WAVE, GUIDE, BYE)}
    assert counts == {behaviours.WAVE: 249, GUIDE: 10, BYE: 10}
    for behaviour in ("guide", "bye"):
        assert sorted(t.style for t in sets[f"{behaviour}_test"]) == sorted(held_out)
        assert {t.style for t in sets[f"{behaviour}_seen"]} == set(GESTURE_STYLES) - held_out


@needs_data
def test_guide_and_bye_takes_are_labelled_as_behaviours_of_their_own(tmp_path):
    guide = realmocap.import_real_clip(REALMOCAP_DIR / "guide" / "dataset-1_guide_normal_001.bvh", tmp_path,
                                       GESTURE_LABELS)
    assert (guide.behaviour, guide.behaviour_kind, guide.arm) == (GUIDE, behaviours.TARGET, "RIGHT")
    to_target = np.asarray(guide.target) - skeleton.shoulder_rest_position(guide.arm)
    assert np.allclose(to_target, realmocap_takes.GUIDE_TARGET_DISTANCE * np.asarray(guide.attributes))
    bye = realmocap.import_real_clip(REALMOCAP_DIR / "bye" / "dataset-1_bye_normal_001.bvh", tmp_path,
                                     GESTURE_LABELS)
    assert (bye.behaviour, bye.behaviour_kind, bye.arm) == (BYE, behaviours.INTENSITY, "RIGHT")
    assert 0.0 <= bye.exaggeration <= 1.0 and bye.attributes == bye.exaggeration
    paper = realmocap.import_real_clip(REALMOCAP_DIR / "bye" / "dataset-1_bye_normal_001.bvh", tmp_path)
    assert (paper.behaviour, paper.exaggeration) == (behaviours.WAVE, bye.exaggeration)
