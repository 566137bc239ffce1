"""A run's settings: checked before any work (each bad value named with its fix, nothing written); a new run
takes the defaults, a resumed run its checkpoint's settings, and a conflicting value is refused naming it."""
import pytest
import torch

from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent import checkpoint
from trainer.experiments.run import NEW_RUN_DEFAULTS, RunSettings, resolve

SAVED = {"behaviour": "wave", "clips": "clips/manifest.json", "preset": "debug", "variant": "single_state",
         "seed": 4, "eval_every": 3, "epochs": 7}


def test_a_new_run_takes_the_defaults_and_keeps_what_is_given(tmp_path):
    settings = resolve(RunSettings(output=str(tmp_path), seed=9))
    assert settings.seed == 9 and settings.epochs is None
    assert {name: getattr(settings, name) for name in NEW_RUN_DEFAULTS if name != "seed"} == \
        {name: value for name, value in NEW_RUN_DEFAULTS.items() if name != "seed"}


def test_a_resumed_run_takes_its_checkpoints_settings(tmp_path):
    checkpoint.save(tmp_path / checkpoint.FILENAME, {"epoch": 0}, SAVED)
    settings = resolve(RunSettings(output=str(tmp_path), resume=True, seed=4))  # the same seed is no conflict
    assert {name: getattr(settings, name) for name in SAVED} == SAVED
    assert resolve(RunSettings(output=str(tmp_path), resume=True, epochs=12)).epochs == 12  # run it longer


def test_a_conflicting_value_on_resume_is_refused_naming_it(tmp_path):
    checkpoint.save(tmp_path / checkpoint.FILENAME, {"epoch": 0}, SAVED)
    with pytest.raises(RLAnimateError, match=r"--preset default \(the run has debug\), --seed 0 \(the run has 4\)"):
        resolve(RunSettings(output=str(tmp_path), resume=True, seed=0, preset="default"))


@pytest.mark.parametrize("values, message", [
    (dict(epochs=0), r"--epochs 0: train at least 1 epoch \(leave --epochs out for the preset's length"),
    (dict(epochs=-3), r"--epochs -3: train at least 1 epoch"),
    (dict(checkpoint_every=0), r"--checkpoint-every 0: write a checkpoint every 1 or more epochs"),
    (dict(eval_every=-1), r"--eval-every -1: evaluate every N >= 1 epochs, or 0 for only at the end"),
    (dict(seed=-1), r"--seed -1: use a seed from 0 to 4294967295"),
    (dict(preset="huge"), r"--preset huge: unknown config preset; use one of debug, default, paper"),
    (dict(epochs=0, checkpoint_every=0), r"--epochs 0: .*; --checkpoint-every 0: .*\. Nothing was trained\."),
])
def test_unusable_settings_are_refused_before_any_work(tmp_path, values, message):
    output = tmp_path / "run"
    with pytest.raises(RLAnimateError, match=message):
        resolve(RunSettings(output=str(output), **values))
    assert not output.exists(), "nothing is written"


def test_resuming_with_fewer_epochs_than_the_run_has_trained_is_refused(tmp_path):
    arguments = {"behaviour": "both", "clips": "clips/manifest.json", "preset": "debug", "variant": "rlanimate",
                 "seed": 0, "eval_every": 10, "epochs": 20}
    checkpoint.save(tmp_path / checkpoint.FILENAME, {"epoch": 12, "weights": torch.zeros(3)}, arguments)
    before = (tmp_path / checkpoint.FILENAME).read_bytes()
    with pytest.raises(RLAnimateError, match=r"--epochs 5, but the run in .* has trained 12 epochs already: give 12 "
                                             r"or more to finish or extend it"):
        resolve(RunSettings(output=str(tmp_path), resume=True, epochs=5))
    assert (tmp_path / checkpoint.FILENAME).read_bytes() == before
    assert resolve(RunSettings(output=str(tmp_path), resume=True, epochs=30)).epochs == 30
    assert resolve(RunSettings(output=str(tmp_path), resume=True)).epochs == 20
