"""trainer/train.py (the shim for trainer.scripts.train) as a subprocess on a tiny FBX clip library: its
outputs exist and load without torch."""
import json
import re
import subprocess
import sys

import numpy as np
import pytest
from test_settings_cli import help_entries

from rlanimate_addon.core import runtime
from trainer.agent.algorithm import clip_objective
from trainer.agent.config import load_preset
from trainer.blender_io.clip_import import load_clip_set
from trainer.experiments.run import NEW_RUN_DEFAULTS, RunSettings
from trainer.paths import REPO_ROOT
from trainer.scripts import cli, train


def test_blender_style_arguments_are_parsed_after_the_double_dash():
    argv = ["blender", "-b", "-P", "trainer/train.py", "--", "--preset", "debug", "--behaviour", "wave"]
    settings = train.parse_settings(argv)
    assert (settings.run.preset, settings.run.behaviour, settings.run.variant, settings.install) == (
        "debug", "wave", None, False)


def test_every_option_train_had_parses_with_its_meaning(capsys):
    argv = ["train.py", "--behaviour", "point,beckon", "--clips", "takes", "--hold-out", "0.3", "--epochs", "7",
            "--seed", "4", "--output", "runs/x", "--preset", "paper", "--variant", "supervised", "--resume",
            "--overwrite", "--allow-new-behaviour", "--install", "--eval-every", "0", "--checkpoint-every", "2",
            "--quiet", "--verbose", "--import-workers", "3", "--import-memory-limit", "1.5",
            "--import-time-limit", "30"]
    assert train.parse_settings(argv) == train.TrainSettings(
        RunSettings(output="runs/x", behaviour="point,beckon", clips="takes", epochs=7, seed=4, preset="paper",
                    variant="supervised", eval_every=0, resume=True, overwrite=True, allow_new_behaviour=True,
                    checkpoint_every=2),
        hold_out=0.3, install=True, quiet=True, verbose=True, import_workers=3, import_memory_limit=1.5,
        import_time_limit=30.0)
    with pytest.raises(SystemExit) as exit_:
        train.parse_settings(["train.py", "--variant", "rlanimat"])
    assert exit_.value.code == 2 and "rlanimat" in capsys.readouterr().err


def test_the_help_names_the_defaults_a_new_run_takes(capsys, monkeypatch):
    entries = help_entries(train.TrainSettings, capsys, monkeypatch)
    for name in ("behaviour", "seed", "preset", "variant", "eval_every"):
        entry = next(entry for entry in entries if entry.startswith("--" + name.replace("_", "-") + " "))
        assert re.search(rf"\(.*None: {NEW_RUN_DEFAULTS[name]}[;)]", entry), entry


def test_train_cli_writes_an_agent_report_and_plots_that_load(tiny_library, tmp_path):
    output = tmp_path / "run"
    command = [sys.executable, str(REPO_ROOT / "trainer" / "train.py"), "--preset", "debug", "--output",
               str(output), "--clips", str(tiny_library), "--epochs", "3", "--eval-every", "2"]
    result = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    for name in ("agent.npz", "checkpoint.pt", "metrics.jsonl", "report.json", "report.md", "training_curves.png"):
        assert (output / name).stat().st_size > 0, name
    metrics = [json.loads(line) for line in (output / "metrics.jsonl").read_text().splitlines()]
    assert [m["epoch"] for m in metrics] == [1, 2, 3] and "unseen/score" in metrics[1]
    report = json.loads((output / "report.json").read_text())
    random_targets = load_preset("debug")[1].random_targets  # pointing requests at new targets per epoch
    assert report["episodes"] == 3 * (2 + random_targets) and len(report["held_out"]["clips"]) == 2
    assert len(report["training"]["clips"]) == 4  # the 10 seen clips, capped at the library's 4
    assert (output / "training_curves.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    agent = runtime.load_agent(output / "agent.npz")  # numpy only: no torch, no pickle
    clip = load_clip_set(tiny_library).test[0]
    actions = agent.rollout(clip_objective(agent.space, clip))
    assert actions.shape == (len(clip.rotvecs), 45) and np.all((actions >= 0) & (actions <= 1))


def test_unknown_preset_is_a_clear_error_before_any_clip_loads(tiny_library, tmp_path, capsys):
    argv = ["train.py", "--preset", "huge", "--output", str(tmp_path / "run"), "--clips", str(tiny_library)]
    assert cli.run_main(train.main, argv) == 2
    assert "--preset huge: unknown config preset; use one of debug" in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("option, value, message", [
    ("--epochs", "0", "--epochs 0: train at least 1 epoch"),
    ("--epochs", "-3", "--epochs -3: train at least 1 epoch"),
    ("--checkpoint-every", "0", "--checkpoint-every 0: write a checkpoint every 1 or more epochs"),
    ("--import-memory-limit", "0", "--import-memory-limit 0: give a number above 0 (GB), such as 2"),
    ("--import-time-limit", "-5", "--import-time-limit -5: give a number above 0 (seconds), such as 60"),
    ("--import-workers", "0", "--import-workers 0: give a number above 0, such as 2"),
])
def test_unusable_arguments_stop_the_script_before_any_clip_is_imported(tmp_path, monkeypatch, capsys, option,
                                                                        value, message):
    def no_import(clips):
        raise AssertionError("the clips were imported before the arguments were checked")

    monkeypatch.setattr(train, "LibrarySession", no_import)
    argv = ["train.py", "--preset", "debug", "--output", str(tmp_path / "run"), option, value]
    assert cli.run_main(train.main, argv) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("output, message", [
    ("a_file/run", "a_file is a file, not a folder; choose a folder for the run's outputs"),
    ("/sys/rlanimate_run", "cannot write in /sys (Permission denied); choose a folder you can write to"),
])
def test_an_output_that_cannot_be_written_is_refused_before_any_clip_is_imported(tmp_path, monkeypatch, capsys,
                                                                                 output, message):
    def no_import(clips, verbose=False):
        raise AssertionError("the clips were imported before --output was checked")

    monkeypatch.setattr(train, "LibrarySession", no_import)
    (tmp_path / "a_file").write_text("not a folder")
    output = output if output.startswith("/") else str(tmp_path / output)
    assert cli.run_main(train.main, ["train.py", "--preset", "debug", "--output", output]) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"error: --output {output}: ") and message in error and "Nothing was trained." in error
    assert (tmp_path / "a_file").read_text() == "not a folder"
