"""docs/results/realmocap.md's per-style table (takes grouped by the style in their file names) and
seeds table (each seed, their mean ± sd, and retrieval)."""
from trainer.reporting.realmocap_report import per_style_rows, seed_rows


def _clip(style, take, score, swing, accepted):
    return {"name": f"dataset-2_wave-left-hand_{style}_{take:03d}", "score": score, "aligned_score": score + 5.0,
            "swing_ratio": swing, "frequency_ratio": 1.0, "wave_accepted": float(accepted)}


def test_per_style_rows_group_takes_by_style_and_keep_the_methods_order():
    methods = {
        "rlanimate": {"clips": [_clip("normal", 9, 60.0, 0.5, False), _clip("active", 9, 40.0, 0.2, False),
                                _clip("normal", 10, 80.0, 0.9, True)]},
        "nearest_clip": {"clips": [_clip("normal", 9, 70.0, 1.0, True), _clip("active", 9, 50.0, 1.1, True),
                                   _clip("normal", 10, 90.0, 1.2, True)]},
    }
    rows = per_style_rows("takes 009-010", methods)
    assert [row[1:3] for row in rows] == [["active", "RLAnimate"], ["active", "Nearest clip"],
                                          ["normal", "RLAnimate"], ["normal", "Nearest clip"]]
    normal_agent = rows[2]
    assert normal_agent[3:] == [2, "70.0", "75.0", "0.70", "1.00", "1/2"]


def _seed(score, aligned, swing, accepted):
    return {"clips": 2, "score": score, "smoothness": 99.0, "aligned_score": aligned, "swing_ratio_median": swing,
            "frequency_ratio_median": 1.0, "accepted": accepted}


def _retrieval(aligned):
    wave = {"aligned_score": aligned, "swing_ratio_median": 1.0, "frequency_ratio_median": 1.0, "accepted_share": 0.5}
    return {"clips": [{}, {}], "score": 70.0, "smoothness": 99.5, "by_behaviour": {"wave": wave}}


def test_seed_rows_give_each_seed_then_their_mean_and_sd_then_retrieval():
    agent = {"clips": [{}, {}]}
    results = {"wave": {"test": {"rlanimate": agent, "nearest_clip": _retrieval(81.0)},
                        "test_seeds": {"0": _seed(60.0, 80.0, 0.9, 1), "1": _seed(64.0, 84.0, 1.1, 2)},
                        "bye": {"rlanimate": agent, "nearest_clip": _retrieval(30.0)},
                        "bye_seeds": {"0": _seed(20.0, 35.0, 0.5, 0)}},
               "holdout": {"test": {"rlanimate": agent, "nearest_clip": _retrieval(45.0)},
                           "test_seeds": {"0": _seed(40.0, 45.0, 0.6, 0), "1": _seed(40.0, 47.0, 0.8, 1)}}}
    rows = seed_rows(results)
    assert [row[:2] for row in rows[:4]] == [["takes 009-010", "RLAnimate, seed 0"], ["takes 009-010", "RLAnimate, seed 1"],
                                             ["takes 009-010", "RLAnimate, mean ± sd of 2"],
                                             ["takes 009-010", "Nearest clip"]]
    assert rows[2][2:5] == ["**62.0 ± 2.8**", "**82.0 ± 2.8**", "**1.00 ± 0.14**"]
    assert rows[3][3] == "81.0" and rows[3][6] == "1"
    # One seed: no mean row.
    assert [row[1] for row in rows[4:6]] == ["RLAnimate, seed 0", "Nearest clip"]
