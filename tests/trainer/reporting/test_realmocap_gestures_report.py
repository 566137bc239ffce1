"""The guide and goodbye page's counts: guide acceptance and form of generated and real takes, raised starts."""
from rlanimate_addon.core import behaviour_metrics
from trainer.reporting import realmocap_gestures_report as report

HELD = {"heading_error": 5.0, "palm_up": 20.0, "reach": 0.9, "extension": 0.95, "hold_s": 1.0, "free_arm_rise": 0.02}


def _row(measures, reference):
    return {**measures, **{f"reference_{k}": v for k, v in reference.items()}}


def test_guide_counts_tell_acceptance_from_form_for_generated_and_real_takes():
    brief = {**HELD, "hold_s": 0.2}  # the form without the hold: not accepted, still the form
    off_target = {**HELD, "heading_error": behaviour_metrics.GUIDE_HEADING_DEG + 1.0}
    palm_down = {**HELD, "palm_up": 170.0}
    rows = [_row(HELD, brief), _row(brief, HELD), _row(off_target, off_target), _row(palm_down, HELD)]
    assert report.guide_counts(rows) == ("1 / 4", "2 / 4")
    assert report.guide_counts(rows, reference=True) == ("2 / 4", "3 / 4")


def test_raised_starts_name_the_goodbye_takes_that_begin_mid_gesture():
    def rows(*elevations):
        return {"rlanimate": {"clips": [{"name": f"dataset-1_bye_{style}_001", "elevation_reference_first": e}
                                        for style, e in elevations]}}
    results = {"sets": {"bye_seen": rows(("giant", 157.0), ("sad", 17.0)), "bye_test": rows(("chimpira", 88.0),
                                                                                              ("musical", 23.0))}}
    assert report.raised_starts(results) == ["chimpira", "giant"]


def test_seed_rows_give_each_seed_their_spread_and_retrieval():
    def summary(score, accepted):
        return {"clips": 4, "score": score, "aligned_score": score + 10.0, "accepted": accepted}
    sets = {key: {"rlanimate": {"0": summary(10.0, 1), "1": summary(20.0, 3)}, "nearest_clip": summary(30.0, 2)}
            for key, _, _ in report.SETS[:3]}
    rows = report.seed_rows({"seed_sets": sets})
    assert len(rows) == 3 * 4
    assert rows[2][1:] == ["RLAnimate, mean ± sd of 2", "**15.00 ± 7.07**", "**25.00 ± 7.07**", "**2.00 ± 1.41**"]
    assert rows[3][1:] == ["Nearest clip", "30.00", "40.00", "2 / 4"]
    one_seed = {key: {**entry, "rlanimate": {"0": entry["rlanimate"]["0"]}} for key, entry in sets.items()}
    assert [row[1] for row in report.seed_rows({"seed_sets": one_seed})[:2]] == ["RLAnimate, seed 0", "Nearest clip"]
