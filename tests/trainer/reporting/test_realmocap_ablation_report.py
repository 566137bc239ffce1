"""docs/results/realmocap_ablation.md: each setting against the agent as exported, seeded groups as their mean,
retrieval last, and per-style rows for the deterministic settings only."""
from trainer.reporting.realmocap_ablation_report import ablation_markdown, findings, style_rows


def _summary(score, aligned):
    style = {"takes": 2, "score": score, "aligned_score": aligned, "swing_ratio": 1.0, "frequency_ratio": 1.1,
             "elevation_last_error": 3.0, "accepted": 1}
    return {"clips": 2, "score": score, "aligned_score": aligned, "swing_ratio_median": 1.0,
            "frequency_ratio_median": 1.1, "elevation_last_error_median": 3.0, "accepted": 1,
            "by_style": {"normal": style}}


def _results():
    names = ["typical tempo (as exported)", "mean rhythm, all waves' phase", "sampled states 1: x",
             "sampled states 2: x", "seed 1: y", "seed 2: y"]
    scores = [(60.0, 70.0), (62.5, 71.0), (50.0, 65.0), (54.0, 67.0), (40.0, 60.0), (44.0, 62.0)]
    summaries = {name: _summary(*score) for name, score in zip(names, scores, strict=True)}
    summaries["nearest_clip"] = _summary(74.0, 90.0)
    summaries["nearest_clip, tempo asked"] = _summary(80.0, 95.0)
    return {"command": "cmd", "seed": 0, "epochs": 50, "preset": "default", "variants": names,
            "experiments": {"wave": {"test_set": "takes 009-010", "test_clips": 2, "train_seconds": 100.0,
                                     "evaluation_cpu_seconds": 10.0, "summaries": summaries, "phase_of_all": 0.05,
                                     "style_phases": {"active": {"phase": -0.5, "concentration": 0.9, "waves": 4}},
                                     "rule_checks": {rule: {"waves": 4, "rate_within": within,
                                                            "median_log_rate_error": 0.07, "signal_correlation": 0.2}
                                                     for rule, within in (("typical tempo", 0.9),
                                                                          ("mean rhythm", 0.75))}}}}


def test_findings_compare_each_setting_with_the_agent_as_trained_and_average_seeded_groups():
    line = findings(_results())[0]
    assert "as exported 60.0 / 70.0" in line and "mean rhythm, all waves' phase: 62.5 / 71.0 (+2.5 / +1.0)" in line
    assert "sampled states (mean of 2 seeds): 52.0 / 66.0" in line and "seed (mean of 2 seeds): 42.0 / 61.0" in line
    assert line.endswith("retrieval 74.0 / 90.0; retrieval, tempo asked 80.0 / 95.0.")
    assert findings(_results())[1].endswith("(trainer/evaluation/rhythm_leave_one_out.py; no test take): typical "
                                            "tempo: 90% within 0.8-1.25x, median |log rate ratio| 0.070, signal "
                                            "correlation 0.20; mean rhythm: 75% within 0.8-1.25x, median |log rate "
                                            "ratio| 0.070, signal correlation 0.20.")
    assert findings(_results())[2].endswith("waves): active -0.50 (0.90, 4); of all of them +0.05.")


def test_per_style_rows_leave_out_the_seeded_settings():
    results = _results()
    page = ablation_markdown(results)
    rows = [line for line in page.splitlines() if line.startswith("| takes 009-010 | normal |")]
    assert [row.split(" | ")[2] for row in rows] == ["typical tempo (as exported)",
                                                     "mean rhythm, all waves' phase", "Nearest clip (retrieval)",
                                                     "Nearest clip (retrieval), tempo asked"]
    assert rows[1].endswith("| 62.5 | 71.0 | 1.00 | 1.10 | 3.0 | 1 / 2 |")
    assert len(style_rows(results, ["nearest_clip"])) == 1
