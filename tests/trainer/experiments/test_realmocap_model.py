"""The model search on real capture's validation takes (trainer/experiments/realmocap_model.py): its settings, the
issue's bars read from a scoring result, and its page."""
import pytest

from rlanimate_addon.core.errors import RLAnimateError
from trainer.experiments.realmocap_model import ModelSettings, validation_summary
from trainer.reporting.realmocap_model_report import model_markdown, model_rows
from trainer.scripts.realmocap_model import parse_settings


def _clip(style, take, smoothness, last_error, score=80.0):
    return {"name": f"dataset-2_wave-left-hand_{style}_{take:03d}", "score": score, "aligned_score": score + 5.0,
            "smoothness": smoothness, "swing_ratio": 1.0, "frequency_ratio": 1.0, "elevation_last_error": last_error,
            "wave_accepted": 1.0}


def _result(clips):
    wave = {"aligned_score": 85.0, "swing_ratio_median": 1.0, "frequency_ratio_median": 1.0,
            "elevation_last_error_median": 2.0, "accepted_share": 1.0}
    return {"clips": clips, "score": 80.0, "smoothness": 99.0, "by_behaviour": {"wave": wave}}


def test_the_summary_counts_the_rough_takes_and_names_the_worst_styles_last_frame():
    summary = validation_summary(_result([_clip("normal", 7, 98.4, 3.0), _clip("normal", 8, 99.5, 5.0),
                                          _clip("active", 7, 99.0, 1.0), _clip("active", 8, 98.6, 2.0)]))
    assert (summary["rough_takes"], summary["smoothness_min"]) == (1, 98.4)
    assert summary["worst_style_last_error"] == 4.0, "normal's median of 3 and 5"
    assert summary["take_scores"]["score"] == [80.0] * 4


def test_unknown_presets_or_experiments_are_refused_before_any_training():
    with pytest.raises(RLAnimateError, match="unknown huge"):
        ModelSettings(presets=("end_chunks", "huge"))
    with pytest.raises(RLAnimateError, match="unknown later"):
        ModelSettings(experiments=("later",))
    settings = parse_settings(["prog", "--presets", "end_chunks", "end_chunks_long", "--seeds", "0", "1"])
    assert (settings.presets, settings.seeds, settings.experiments) == (("end_chunks", "end_chunks_long"), (0, 1),
                                                                        ("takes", "style"))


def test_the_page_gives_each_preset_over_its_seeds_beside_retrieval():
    summary = validation_summary(_result([_clip("normal", 7, 99.0, 3.0), _clip("active", 7, 98.0, 6.0)]))
    better = {**summary, "score": 90.0, "aligned_score": 95.0}
    results = {"command": "nice ...", "epochs": 100, "seeds": [0, 1], "experiments": {"takes": {
        "validates": "takes 007-008", "train_clips": 200, "validation_clips": 2,
        "retrieval": {"paper": summary, "_tempo": summary},
        "presets": {"end_chunks": {"0": {"train_cpu_seconds": 500.0, "paper": summary, "_tempo": summary},
                                   "1": {"train_cpu_seconds": 520.0, "paper": better, "_tempo": better}}}}}}
    rows = model_rows(results)
    assert rows[0][:4] == ["takes 007-008 (2)", "label only (the paper's)", "`end_chunks` (2 seeds)", "85.0 ± 7.1"]
    assert rows[0][-2:] == ["6.0 ± 0.0", "510"] and rows[1][2] == "Nearest clip" and rows[1][-1] == ""
    page = model_markdown(results)
    assert "| takes 007-008 | active | 85.0 | 85.0 |" in page
