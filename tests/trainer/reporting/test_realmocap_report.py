"""docs/results/realmocap.md's per-style table (takes grouped by the style in their file names) and
seeds table (each seed, their mean ± sd, and retrieval), and what tempo each test style's label can reach."""
import numpy as np

from trainer.reporting import realmocap_report
from trainer.reporting.realmocap_report import per_style_rows, reach_rows, seed_rows, style_summaries


def _clip(style, take, score, swing, accepted, elevation=2.0):
    return {"name": f"dataset-2_wave-left-hand_{style}_{take:03d}", "score": score, "aligned_score": score + 5.0,
            "swing_ratio": swing, "frequency_ratio": 1.0, "elevation_last_error": elevation,
            "wave_accepted": float(accepted)}


def test_style_summaries_group_takes_by_the_style_in_their_names():
    summaries = style_summaries(
        {
            "clips": [
                _clip("normal", 9, 60.0, 0.5, False, 12.0),
                _clip("active", 9, 40.0, 0.2, False),
                _clip("normal", 10, 80.0, 0.9, True, 4.0),
            ]
        }
    )
    assert list(summaries) == ["active", "normal"]
    undefined = style_summaries({"clips": [_clip("elderly", 1, 50.0, float("nan"), False)]})["elderly"]
    assert np.isnan(undefined["swing_ratio"]) and undefined["frequency_ratio"] == 1.0
    assert summaries["normal"] == {"takes": 2, "score": 70.0, "aligned_score": 75.0, "swing_ratio": 0.7,
                                   "frequency_ratio": 1.0, "elevation_last_error": 8.0, "accepted": 1}


def test_per_style_rows_give_rlanimate_over_seeds_then_the_baselines():
    agent = [_clip("normal", 9, 60.0, 0.5, False, 12.0), _clip("active", 9, 40.0, 0.2, False),
             _clip("normal", 10, 80.0, 0.9, True, 4.0)]
    other_seed = [dict(clip, score=clip["score"] + 10.0, swing_ratio=1.0) for clip in agent]
    methods = {"rlanimate": {"clips": agent},
               "nearest_clip": {"clips": [_clip("normal", 9, 70.0, 1.0, True), _clip("active", 9, 50.0, 1.1, True),
                                          _clip("normal", 10, 90.0, 1.2, True)]}}
    seeds = {"0": {"by_style": style_summaries({"clips": agent})},
             "1": {"by_style": style_summaries({"clips": other_seed})}}
    rows = per_style_rows("takes 009-010", methods, seeds)
    assert [row[1:3] for row in rows] == [["active", "RLAnimate, mean ± sd of 2 seeds"], ["active", "Nearest clip"],
                                          ["normal", "RLAnimate, mean ± sd of 2 seeds"], ["normal", "Nearest clip"]]
    assert rows[2][3:] == [2, "75.0 ± 7.1", "75.0 ± 0.0", "0.85 ± 0.21", "1.00 ± 0.00", "8.0 ± 0.0", "1.0 ± 0.0 / 2"]
    assert rows[3][3:] == [2, "80.0", "85.0", "1.10", "1.00", "2.0", "2 / 2"]
    one_seed = per_style_rows("takes 009-010", methods, {"0": seeds["0"]})
    assert one_seed[2][2:] == ["RLAnimate, seed 0", 2, "70.0", "75.0", "0.70", "1.00", "8.0", "1 / 2"]


def _seed(score, aligned, swing, accepted):
    return {"clips": 2, "score": score, "smoothness": 99.0, "aligned_score": aligned, "swing_ratio_median": swing,
            "frequency_ratio_median": 1.0, "elevation_last_error_median": 3.0, "accepted": accepted}


def _retrieval(aligned):
    wave = {"aligned_score": aligned, "swing_ratio_median": 1.0, "frequency_ratio_median": 1.0,
            "elevation_last_error_median": 2.0, "accepted_share": 0.5}
    return {"clips": [_clip("normal", 9, 70.0, 1.0, True), _clip("normal", 10, 70.0, 1.0, False)], "score": 70.0,
            "smoothness": 99.5, "by_behaviour": {"wave": wave}}


def test_seed_rows_give_each_seed_then_their_mean_and_sd_then_retrieval():
    agent = {"clips": [{}, {}]}
    results = {"wave": {"test": {"rlanimate": agent, "nearest_clip": _retrieval(81.0)},
                        "test_seeds": {"0": _seed(60.0, 80.0, 0.9, 1), "1": _seed(64.0, 84.0, 1.1, 2)},
                        "bye": {"rlanimate": agent, "nearest_clip": _retrieval(30.0)},
                        "bye_seeds": {"0": _seed(20.0, 35.0, 0.5, 0)}},
               "holdout": {"test": {"rlanimate": agent, "nearest_clip": _retrieval(45.0)},
                           "test_seeds": {"0": _seed(40.0, 45.0, 0.6, 0), "1": _seed(40.0, 47.0, 0.8, 1)},
                           "test_tempo": {"rlanimate": agent, "nearest_clip": _retrieval(41.0)},
                           "test_tempo_seeds": {"0": _seed(50.0, 55.0, 0.9, 1)}}}
    rows = seed_rows(results)
    assert rows[-2:] == [
        ["unseen styles, tempo asked", "RLAnimate, seed 0", "50.0", "55.0", "0.90", "1.00", "3.0", "1"],
        ["unseen styles, tempo asked", "Nearest clip", "70.0", "41.0", "1.00", "1.00", "2.0", "1"],
    ]
    assert [row[:2] for row in rows[:4]] == [
        ["takes 009-010", "RLAnimate, seed 0"],
        ["takes 009-010", "RLAnimate, seed 1"],
        ["takes 009-010", "RLAnimate, mean ± sd of 2"],
        ["takes 009-010", "Nearest clip"],
    ]
    assert rows[2][2:5] == ["**62.0 ± 2.8**", "**82.0 ± 2.8**", "**1.00 ± 0.14**"]
    assert rows[2][6] == "**3.0 ± 0.0**" and rows[3][3] == "81.0" and rows[3][6:] == ["2.0", "1"]
    # One seed: no mean row.
    assert [row[1] for row in rows[4:6]] == ["RLAnimate, seed 0", "Nearest clip"]


def _reach(style, in_reach_styles, lowest, in_band):
    near = {str(w): {"waves": 10 * k, "styles": ["feminine", "normal"][:k], "in_reach": len(in_reach_styles) * k,
                     "in_reach_styles": in_reach_styles} for k, w in enumerate((0.05, 0.1, 0.2), start=0)}
    return {"styles": {style: {"takes": 20, "labels": (0.2, 0.34), "tempo_hz": 0.87, "near": near,
                               "rules": {"in_band": in_band, "lowest": lowest, "highest": lowest + 1.0}}},
            "rules": 72, "in_band_in_every_style": in_band}


def test_reach_rows_give_each_test_style_its_neighbours_in_reach_and_the_rules_range():
    rows = reach_rows({"label_reach": {"wave": _reach("masculine", ["masculine"], 1.04, 27),
                                       "holdout": _reach("elderly", [], 1.91, 0)}})
    assert rows[0] == ["takes 009-010", "masculine", "20", "0.20-0.34", "0.87", "0/0, 1/10, 2/20",
                       "feminine, normal", "masculine", "1.04-2.04 (27/72)"]
    assert rows[1][:2] == ["unseen styles", "elderly"] and rows[1][5:] == ["0/0, 0/10, 0/20", "feminine, normal",
                                                                          "none", "1.91-2.91 (0/72)"]


def _scored(scores, aligned):
    return {"clips": [{"score": s, "aligned_score": a} for s, a in zip(scores, aligned, strict=True)]}


def test_both_requests_sit_side_by_side_with_the_paired_gap_over_the_seeds_mean():
    """Each set asked both ways on one row each: RLAnimate over its seeds, retrieval, and the gap of the per-take
    mean over seeds against retrieval on the same takes, with its 95% interval; fallbacks named below."""
    seeds = {"0": {"score": 70.0, "aligned_score": 80.0, "take_scores": {"score": [60.0, 80.0],
                                                                          "aligned_score": [70.0, 90.0]}},
             "1": {"score": 74.0, "aligned_score": 84.0, "take_scores": {"score": [64.0, 84.0],
                                                                          "aligned_score": [74.0, 94.0]}}}
    retrieval = _scored([61.0, 81.0], [80.0, 80.0])
    tempo = {"rlanimate": {**_scored([0.0, 0.0], [0.0, 0.0]), "tempo_fallbacks": {"take_019": "too short"}},
             "nearest_clip": retrieval}
    results = {"wave": {"test": {"rlanimate": _scored([0.0, 0.0], [0.0, 0.0]), "nearest_clip": retrieval},
                        "test_seeds": seeds, "test_tempo": tempo, "test_tempo_seeds": {"0": seeds["0"]}}}
    rows = realmocap_report.both_request_rows(results)
    assert [row[:2] for row in rows] == [["takes 009-010", "the paper's (label only)"],
                                         ["takes 009-010", "tempo asked"]]
    assert rows[0][2:4] == ["72.0 ± 2.8 / 82.0 ± 2.8", "71.0 / 80.0"]
    # per take: 62 - 61 and 82 - 81 -> +1.0 exactly; DTW 72 - 80 and 92 - 80 -> +2.0, wide interval
    assert rows[0][4] == "+1.0 (+1.0 to +1.0)" and rows[0][5].startswith("+2.0 (-") and rows[0][6] == "2"
    assert rows[1][2] == "70.0 / 80.0" and rows[1][6] == "1"
    assert realmocap_report.fallback_notes(results) == [
        "- takes 009-010, tempo asked: 1 take(s) asked with the label alone: take_019 (too short)."]
