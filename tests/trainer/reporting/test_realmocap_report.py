"""docs/results/realmocap.md's per-style table: takes grouped by the style in their file names."""
from trainer.reporting.realmocap_report import per_style_rows


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
