"""trainer.scripts.experiments' command line: another seed gets its own runs and results, never seed 0's."""
from pathlib import Path

from trainer.evaluation.experiments import run_folder
from trainer.paths import REPO_ROOT, RESULTS_DIR
from trainer.scripts import experiments


def test_seed_zero_uses_the_shared_folders():
    options = experiments.parse_options(["experiments", "--seed", "0"])
    assert Path(options.runs) == REPO_ROOT / "runs" / "experiments"
    assert Path(options.results) == RESULTS_DIR


def test_another_seed_never_reuses_seed_zero_runs_or_overwrites_its_results():
    options = experiments.parse_options(["experiments", "--seed", "3"])
    assert Path(options.runs) == REPO_ROOT / "runs" / "experiments_seed3"
    assert Path(options.results) == RESULTS_DIR / "seed3"
    assert run_folder(options, "rlanimate", "wave") != \
        run_folder(experiments.parse_options(["experiments"]), "rlanimate", "wave")


def test_explicit_folders_win(tmp_path):
    argv = ["experiments", "--seed", "3", "--runs", str(tmp_path / "r"), "--results", str(tmp_path)]
    options = experiments.parse_options(argv)
    assert (Path(options.runs), Path(options.results)) == (tmp_path / "r", tmp_path)
