"""Real motion capture as data: names, splits, the relaxed hand, the missing-folder error."""
from types import SimpleNamespace

import pytest

from rlanimate_addon.core.errors import RLAnimateError
from trainer.motion import realmocap_takes

WAVE_NAMES = [f"dataset-2_wave-{side}-hand_{style}_{take:03d}.bvh" for side in ("left", "right")
              for style in realmocap_takes.STYLES for take in range(1, 11)]
#: Takes 021-036 exist for some styles and arms only: two here.
LATER_NAMES = [f"dataset-2_wave-{side}-hand_{style}_{take:03d}.bvh" for side in ("left", "right")
               for style in realmocap_takes.STYLES for take in (21, 36)]


def test_parse_name_reads_content_arm_style_and_take():
    assert realmocap_takes.parse_name("x/dataset-2_wave-left-hand_feminine_009.bvh") == {
        "content": "wave", "arm": "LEFT", "style": "feminine", "take": "009"}
    assert realmocap_takes.parse_name("dataset-1_guide_not-confident_001.bvh") == {
        "content": "guide", "arm": None, "style": "not-confident", "take": "001"}
    with pytest.raises(RLAnimateError, match="Bandai Namco"):
        realmocap_takes.parse_name("wave_001.bvh")


def test_splits_match_the_experiments():
    clips = [SimpleNamespace(**realmocap_takes.parse_name(name)) for name in WAVE_NAMES + LATER_NAMES]
    train, test = realmocap_takes.wave_split(clips)
    assert (len(train), len(test)) == (112 + 28, 28)
    assert {c.take for c in test} == {"009", "010"} and {"021", "036"} <= {c.take for c in train}
    train, test = realmocap_takes.style_holdout_split(clips)
    assert (len(train), len(test)) == (100 + 20, 40)  # the unseen styles are tested on takes 001-010
    assert not {c.style for c in train} & {c.style for c in test}
    assert {c.take for c in test} == {f"{k:03d}" for k in range(1, 11)}


def test_take_groups_hold_every_read_take_once_and_name_validation_and_test():
    groups = [realmocap_takes.take_group(realmocap_takes.parse_name(name)["take"]) for name in WAVE_NAMES + LATER_NAMES]
    assert None not in groups and set(groups) == set(realmocap_takes.TAKE_GROUPS)
    assert realmocap_takes.TAKE_GROUPS["007-008"] == realmocap_takes.VALIDATION_TAKES
    assert realmocap_takes.TAKE_GROUPS["009-010"] == realmocap_takes.TEST_TAKES
    assert realmocap_takes.take_group("015") is None  # a withheld take is in no group


def test_take_selection_never_reads_the_withheld_takes_011_to_020(tmp_path):
    withheld = [f"dataset-2_wave-left-hand_normal_{take:03d}.bvh" for take in range(11, 21)]
    for name in WAVE_NAMES[:12] + LATER_NAMES[:2] + withheld:
        (tmp_path / name).write_text("not read")  # names only: the selection must not open a file
    chosen = [path.name for path in realmocap_takes.take_paths(tmp_path)]
    assert chosen == sorted(WAVE_NAMES[:12] + LATER_NAMES[:2])
    assert not set(chosen) & set(withheld)
    taken = [SimpleNamespace(**realmocap_takes.parse_name(name)) for name in withheld]
    assert realmocap_takes.wave_split(taken) == realmocap_takes.style_holdout_split(taken) == ([], [])



def test_missing_folder_gets_a_clear_error(tmp_path):
    with pytest.raises(RLAnimateError, match="not at"):
        realmocap_takes.require_realmocap(tmp_path)
