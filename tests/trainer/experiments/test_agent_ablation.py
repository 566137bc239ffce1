"""The agent ablation (trainer.scripts.agent_ablation) with --only: trains and measures the named rows, keeps the
others as they were."""

import json
import shutil

from trainer.experiments import agent_ablation
from trainer.paths import RESULTS_DIR
from trainer.scripts import agent_ablation as script


def test_only_replaces_its_rows_and_keeps_the_others(tmp_path, monkeypatch):
    results = tmp_path / "results"
    results.mkdir()
    shutil.copyfile(RESULTS_DIR / "agent_ablation.json", results / "agent_ablation.json")
    before = json.loads((results / "agent_ablation.json").read_text())
    measured = dict(before["point_no_random_targets"], update_steps=7)
    trained = []
    monkeypatch.setattr(agent_ablation, "LibrarySession", lambda manifest: None)
    monkeypatch.setattr(agent_ablation, "train_runs",
                        lambda runs, address, workers: trained.extend(run.preset for run in runs) or [])
    monkeypatch.setattr(agent_ablation, "measure", lambda path, behaviour, session, targets: measured)
    rerun = ["point_no_pointing_term", "point_random_targets"]
    argv = ["agent_ablation", "--only", *rerun, "--runs",
            str(tmp_path / "runs"), "--results", str(results)]
    assert script.main(argv) == 0
    after = json.loads((results / "agent_ablation.json").read_text())
    assert trained == ["no_pointing_term", "default"]
    assert list(after) == [name for name in agent_ablation.ABLATIONS if name in before or name in rerun]
    assert after["point_no_pointing_term"] == after["point_random_targets"] == measured
    kept = [name for name in before if name not in rerun]
    assert kept and all(after[name] == before[name] for name in kept)
    assert "| neither | 7 |" in (results / "agent_ablation.md").read_text()
