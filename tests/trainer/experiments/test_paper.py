"""trainer.experiments.paper and its script: every seed gets its own runs; Table 4 cells are mean ± sd over seeds."""
import math
from pathlib import Path

from trainer.experiments import paper as harness
from trainer.paths import REPO_ROOT, RESULTS_DIR
from trainer.scripts import experiments


def test_seed_zero_uses_the_shared_folders_and_three_seeds_by_default():
    settings = experiments.parse_settings(["experiments"])
    assert settings.seeds == (0, 1, 2)
    assert harness.run_folder(settings, 0, "rlanimate", "wave") == REPO_ROOT / "runs" / "experiments" / "rlanimate_wave"
    assert Path(settings.results) == RESULTS_DIR


def test_another_seed_never_reuses_seed_zero_runs(tmp_path):
    settings = experiments.parse_settings(["experiments", "--seeds", "0", "3", "--runs", str(tmp_path / "r")])
    assert harness.run_folder(settings, 3, "rlanimate", "wave") == tmp_path / "r_seed3" / "rlanimate_wave"
    assert harness.run_folder(settings, 0, "rlanimate", "wave") == tmp_path / "r" / "rlanimate_wave"
    run = harness.run_settings(settings, 3, "rlanimate", "wave")
    assert (run.seed, run.behaviour, run.resume) == (3, "wave", False)
    assert run.output == str(tmp_path / "r_seed3" / "rlanimate_wave")


def test_aggregate_gives_mean_sd_and_count_and_skips_undefined_ratios():
    per_seed = [{"wave": {"score": 99.0, "swing_ratio_median": 0.5}},
                {"wave": {"score": 98.0, "swing_ratio_median": math.nan}},
                {"wave": {"score": 97.0, "swing_ratio_median": 0.7}}]
    table = harness.aggregate(per_seed)["wave"]
    assert table["score"] == {"mean": 98.0, "sd": 1.0, "n": 3}
    assert table["swing_ratio_median"]["n"] == 2 and abs(table["swing_ratio_median"]["mean"] - 0.6) < 1e-12
    assert harness.aggregate(per_seed[:1])["wave"]["score"] == {"mean": 99.0, "sd": 0.0, "n": 1}
