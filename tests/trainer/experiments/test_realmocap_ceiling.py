"""The real-capture agents' ceiling (trainer/experiments/realmocap_ceiling.py): retrieval that never returns the take
asked for, the paired gaps over seeds, its settings and its page."""
import numpy as np
import pytest

from rlanimate_addon.core.errors import RLAnimateError
from tests.trainer.synthetic_library import make_clip
from trainer.evaluation import baselines
from trainer.experiments.realmocap_ceiling import CeilingSettings, leave_one_out, paired_gaps, trailing_styles
from trainer.reporting.realmocap_ceiling_report import ceiling_markdown, ceiling_rows


def test_leave_one_out_retrieval_answers_each_take_with_another():
    library = [make_clip(name, "WAVE", "RIGHT", e, 90 + 10 * k, hz) for k, (name, e, hz) in
               enumerate((("slow", 0.5, 1.2), ("fast", 0.52, 2.5), ("faster", 0.55, 2.8)))]
    motions = leave_one_out(baselines.NearestClip(library), library, with_tempo=True)
    assert [len(m) for m in motions] == [90, 100, 110], "each answer at its take's length"
    for motion, take in zip(motions, library, strict=True):
        assert not np.allclose(motion, take.rotvecs), f"{take.name} was answered with itself"
    np.testing.assert_allclose(motions[1][-1], library[2].rotvecs[-1], atol=1e-9)  # fast's neighbour is faster


def _summary(score, dtw, takes):
    style = {"aligned_score": dtw}
    return {"score": score, "aligned_score": dtw, "rough_takes": 1, "worst_style_last_error": 3.0,
            "by_style": {"active": style, "normal": style},
            "take_scores": {"score": [score + t for t in takes], "aligned_score": [dtw + t for t in takes]}}


def test_the_gaps_pair_the_seeds_mean_per_take_with_retrieval():
    gaps = paired_gaps({"0": _summary(80.0, 90.0, [0.0, 2.0]), "1": _summary(82.0, 92.0, [0.0, 2.0])},
                       _summary(81.0, 95.0, [0.0, 2.0]))
    assert gaps["score"]["mean"] == pytest.approx(0.0) and gaps["aligned_score"]["mean"] == pytest.approx(-4.0)
    assert gaps["score"]["takes"] == 2


def test_the_page_sets_the_trained_takes_beside_the_test_takes():
    agents = {"0": _summary(80.0, 90.0, [0.0, 2.0]), "1": _summary(82.0, 92.0, [0.0, 2.0])}
    retrieval = _summary(81.0, 95.0, [0.0, 2.0])
    entry = {"takes": 2, "agents": agents, "retrieval": retrieval, "gaps": paired_gaps(agents, retrieval)}
    results = {"command": "nice ...", "epochs": 100, "preset": "end_chunks", "seeds": [0, 1], "train_takes": 249,
               "figure": "paths.png",
               "sets": {name: entry for name in ("trained", "trained_tempo", "test", "test_tempo")}}
    rows = ceiling_rows(results)
    assert len(rows) == 4 and rows[0][0].startswith("takes 007-008, trained on") and rows[2][0].startswith("takes 009")
    assert rows[1][2:6] == ["81.0 ± 1.4 / 91.0 ± 1.4", "81.0 / 95.0", "+0.0 (+0.0 to +0.0)", "-4.0 (-4.0 to -4.0)"]
    page = ceiling_markdown(results)
    assert "| normal | 91.0 | 95.0 | 91.0 | 95.0 |" in page and "](paths.png)" in page


def test_the_figure_shows_the_styles_where_the_agent_trails_most():
    agent, retrieval = _summary(80.0, 90.0, [0.0]), _summary(81.0, 95.0, [0.0])
    agent["by_style"] = {"active": {"aligned_score": 99.0}, "masculine": {"aligned_score": 80.0},
                         "normal": {"aligned_score": 90.0}, "youthful": {"aligned_score": 85.0}}
    retrieval["by_style"] = {style: {"aligned_score": 98.0} for style in agent["by_style"]}
    assert trailing_styles({"agents": {"0": agent}, "retrieval": retrieval}) == ["masculine", "youthful", "normal"]


def test_an_unknown_preset_is_refused_before_any_training():
    with pytest.raises(RLAnimateError, match="not 'huge'"):
        CeilingSettings(preset="huge")
