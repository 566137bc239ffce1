"""The training-length search on real capture: its validation splits hold no test take, the choice of length,
the script's settings and the page (trainer/experiments/realmocap_length.py)."""
from types import SimpleNamespace

import pytest

from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io.fk_env import FKEnvironment
from trainer.blender_io.rig_session import new_empty_scene
from trainer.evaluation import baselines
from trainer.experiments import realmocap, realmocap_length
from trainer.motion import realmocap_takes
from trainer.motion.fk import ClipReferences
from trainer.paths import REALMOCAP_DIR
from trainer.reporting.realmocap_length_report import length_markdown
from trainer.scripts.realmocap_length import parse_settings


def _takes():
    """One clip per style, arm and take a real folder can hold (the withheld takes are never read)."""
    takes = [f"{k:03d}" for k in range(1, 37) if f"{k:03d}" not in realmocap_takes.WITHHELD_TAKES]
    return [SimpleNamespace(style=style, arm=arm, take=take)
            for style in realmocap_takes.STYLES for arm in ("LEFT", "RIGHT") for take in takes]


def test_each_validation_split_trains_within_its_experiments_training_takes_and_validates_on_no_test_take():
    clips = _takes()
    wave_train, wave_test = realmocap_takes.wave_split(clips)
    unseen_train, unseen_test = realmocap_takes.style_holdout_split(clips)
    tests = {id(c) for c in wave_test + unseen_test}
    for split, trained in ((realmocap_takes.take_validation_split, wave_train),
                           (realmocap_takes.style_validation_split, unseen_train)):
        train, validation = split(clips)
        assert train and validation and not {id(c) for c in train} & {id(c) for c in validation}
        assert {id(c) for c in train} <= {id(c) for c in trained} and not {id(c) for c in validation} & tests
    train, validation = realmocap_takes.take_validation_split(clips)
    assert {c.take for c in validation} == {"007", "008"} and len(validation) == 5 * 2 * 2
    assert {c.style for c in validation} == set(realmocap_takes.STYLES) - set(realmocap_takes.HOLDOUT_STYLES)
    assert {c.take for c in train if c.style == "normal"} == set(realmocap_takes.TRAIN_TAKES) - {"007", "008"}
    train, validation = realmocap_takes.style_validation_split(clips)
    assert {c.style for c in validation} == {"normal"}
    assert {c.take for c in validation} == {f"00{k}" for k in range(1, 9)}
    assert {c.style for c in train} == {"active", "feminine", "masculine", "youthful"}


def _summary(score, aligned):
    return {"clips": 4, "score": score, "aligned_score": aligned, "swing_ratio_median": 1.0,
            "frequency_ratio_median": 1.0, "elevation_last_error_median": 3.0, "accepted": 2}


def test_the_chosen_length_has_the_best_mean_over_both_sets_and_the_shorter_wins_a_tie():
    by_length = {50: {"takes": _summary(70, 80), "style": _summary(60, 62)},
                 100: {"takes": _summary(76, 86), "style": _summary(56, 58)},  # better seen, worse unseen: +1 in all
                 200: {"takes": _summary(80, 90), "style": _summary(50, 52)}}
    assert realmocap_length.choose(by_length) == 100
    by_length[50]["style"] = _summary(62, 64)  # now level with 100
    assert realmocap_length.choose(by_length) == 50


def test_the_rhythm_rules_name_their_kernels_and_arms_and_the_first_listed_wins_a_tie():
    assert realmocap_length.rhythm_rule(0.1, 1.1, False) == "sd 0.1, log 1.1"
    assert realmocap_length.rhythm_rule(0.1, 1.1, True) == "sd 0.1, log 1.1, the request's arm's waves"
    rules = {"sd 0.1, log 1.05": {"takes": _summary(69, 80)}, "sd 0.1, log 1.1": {"takes": _summary(72, 78)},
             "sd 0.1, log 1.1, the request's arm's waves": {"takes": _summary(70, 80)}}
    assert realmocap_length.choose(rules) == "sd 0.1, log 1.1"  # level with the arm's at 75, and listed first


def test_the_script_takes_rising_lengths_only():
    settings = parse_settings(["prog", "--lengths", "5", "10", "--exaggeration-kernels", "0.1", "--tempo-kernels",
                               "1.1", "1.2", "--seed", "2"])
    assert (settings.lengths, settings.exaggeration_kernels, settings.tempo_kernels, settings.seed) == (
        (5, 10), (0.1,), (1.1, 1.2), 2)
    assert ("--lengths 5 10 --exaggeration-kernels 0.1 --tempo-kernels 1.1 1.2 --seed 2 --preset end_chunks"
            in realmocap_length.command_line(settings))
    defaults = parse_settings(["prog"])
    assert (defaults.exaggeration_kernels, defaults.tempo_kernels) == (realmocap_length.EXAGGERATION_KERNELS,
                                                                     realmocap_length.TEMPO_KERNELS)
    for lengths in ((10, 5), (), (0, 5)):
        with pytest.raises(RLAnimateError, match="rising epoch counts"):
            realmocap_length.LengthSettings(lengths=lengths)
    for kernels in ((), (1.0, 1.1)):
        with pytest.raises(RLAnimateError, match="rate factors above 1"):
            realmocap_length.LengthSettings(tempo_kernels=kernels)
    for kernels in ((), (0.0, 0.1)):
        with pytest.raises(RLAnimateError, match="positive kernel widths"):
            realmocap_length.LengthSettings(exaggeration_kernels=kernels)


def test_the_page_states_the_choice_and_a_row_per_length_request_and_retrieval():
    entry = {"validates": "takes 007-008", "train_clips": 221, "validation_clips": 28,
             "retrieval": {"paper": _summary(74, 90), "_tempo": _summary(80, 96)},
             "by_length": {str(n): {"train_cpu_seconds": 5.0 * n, "paper": _summary(60 + n / 10, 80),
                                    "_tempo": _summary(70, 85), "scoring_cpu_seconds": 1.0} for n in (50, 100)}}
    check = {"waves": 200, "rate_within": 0.9, "median_log_rate_error": 0.0625, "signal_correlation": 0.2}
    rules = {rule: {"exaggeration_kernel": 0.1, "tempo_kernel": 1.1, "by_arm": rule != "sd 0.1, log 1.1",
                    "sets": {"takes": {"paper": _summary(score, 80), "leave_one_out": check}}}
             for rule, score in (("sd 0.1, log 1.1", 71), ("sd 0.1, log 1.1, the request's arm's waves", 70))}
    page = length_markdown({"command": "cmd", "seed": 0, "preset": "end_chunks", "lengths": [50, 100],
                            "experiments": {"takes": entry}, "chosen": 100, "rhythm_rules": rules,
                            "chosen_rhythm_rule": "sd 0.1, log 1.1"})
    assert "**Chosen: 100 epochs**" in page and "**Chosen: sd 0.1, log 1.1**" in page
    rows = [line for line in page.splitlines() if line.startswith("| takes 007-008 (28) |")]
    assert len(rows) == 6 + 2
    assert rows[-2] == "| takes 007-008 (28) | sd 0.1, log 1.1 | 71.0 | 80.0 | 1.00 | 1.00 | 3.0 | 2/28 | 90% | 0.062 |"
    assert rows[1] == ("| takes 007-008 (28) | the paper's | RLAnimate, 100 epochs | 70.0 | 80.0 | 1.00 | 1.00 | 3.0 "
                       "| 2/28 | 500 |")
    assert rows[2].startswith("| takes 007-008 (28) | the paper's | Nearest clip | 74.0 | 90.0 |")


@pytest.mark.skipif(not (REALMOCAP_DIR / "wave").is_dir(),
                    reason=f"real motion capture not found at {REALMOCAP_DIR} "
                           "(../shared/realmocap/ beside the repository)")
def test_each_length_is_trained_from_the_start_and_scored_on_the_validation_takes(tmp_path):
    new_empty_scene()
    clips = [realmocap.import_real_clip(REALMOCAP_DIR / "wave" / f"dataset-2_wave-left-hand_{name}.bvh",
                                        tmp_path / "cache")
             for name in ("feminine_001", "feminine_002", "active_002", "active_007")]
    settings = realmocap_length.LengthSettings(lengths=(1, 2), exaggeration_kernels=(0.1,), tempo_kernels=(1.1, 1.25),
                                               preset="debug", runs=str(tmp_path), workers=1)
    env = FKEnvironment(instances=4)
    results = realmocap_length.length_results({"takes": realmocap_takes.take_validation_split(clips)}, settings, env,
                                              ClipReferences(env))
    entry = results["experiments"]["takes"]
    assert (entry["train_clips"], entry["validation_clips"]) == (3, 1) and list(entry["by_length"]) == ["1", "2"]
    for length in (1, 2):
        report = (tmp_path / f"takes_validation_{length}_debug" / "report.json").read_text()
        assert f'"epochs": {length}' in report
        scored = entry["by_length"][str(length)]
        assert scored["paper"]["clips"] == scored["_tempo"]["clips"] == 1 and scored["train_cpu_seconds"] > 0
    assert entry["retrieval"]["paper"]["score"] > 90.0  # active 002 is the nearest clip to active 007
    assert results["chosen"] in (1, 2) and results["chosen_rhythm_rule"] in results["rhythm_rules"]
    assert list(results["rhythm_rules"]) == ["sd 0.1, log 1.1", "sd 0.1, log 1.25",
                                             "sd 0.1, log 1.1, the request's arm's waves",
                                             "sd 0.1, log 1.25, the request's arm's waves"]
    for played in results["rhythm_rules"].values():  # the chosen length's agent, played with each rule
        assert played["sets"]["takes"]["paper"]["clips"] == 1 and played["sets"]["takes"]["leave_one_out"]["waves"] == 3
    exported = (tmp_path / f"takes_validation_{results['chosen']}_debug" / "agent.npz")
    assert baselines.AgentMethod(exported).agent.rhythm_model.arms == ("LEFT",) * 3  # the waves' arms, kept
