"""What "--behaviour all" trains from a library's behaviours: a library of one behaviour, or one whose every clip
of a behaviour is held out, trains what is there and says what it left out and why; a new behaviour that
fewer than 3 clips name (a typo such as JUMP) is refused naming its clips, unless asked for."""
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from rlanimate_addon.core import runtime
from rlanimate_addon.core.errors import RLAnimateError
from tests.trainer.synthetic_library import make_clip, make_library
from trainer.agent.config import load_preset
from trainer.experiments.run import RunSettings, train
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment

ENV = NumpyFKEnvironment()
LIBRARY = make_library(seed=5)


def _session(train_clips, test_clips):
    return SimpleNamespace(env=ENV, references=ClipReferences(ENV), train_clips=train_clips, test_clips=test_clips,
                           problems=[])


def _of(clips, *names):
    return [clip for clip in clips if clip.behaviour in names]


def _train(session, output, **values):
    return train(RunSettings(output=str(output), preset="debug", seed=1, eval_every=0, progress=False,
                             **{"epochs": 1, **values}), session)


@pytest.mark.parametrize("kept, dropped", [("POINT", "WAVE"), ("WAVE", "POINT")])
def test_a_library_of_one_behaviour_trains_it_and_says_the_other_is_absent(tmp_path, capsys, kept, dropped):
    session = _session(_of(LIBRARY.train, kept), _of(LIBRARY.test, kept))
    report, trainer = _train(session, tmp_path / "run", epochs=None)  # before: IndexError in clips_for_behaviour
    assert trainer.trained == (kept,)
    assert report["epochs"] == load_preset("debug")[1].epochs_single, "one behaviour: the preset's single length"
    assert set(runtime.load_agent(tmp_path / "run" / "agent.npz").behaviours) == {kept}
    assert f"note: training {kept.lower()} only: the library has no {dropped.lower()} clips." in capsys.readouterr().err


def test_a_behaviour_whose_every_clip_is_held_out_is_left_out_with_the_reason(tmp_path, capsys):
    held_out_waves = _of(LIBRARY.train, "WAVE") + _of(LIBRARY.test, "WAVE")
    session = _session(_of(LIBRARY.train, "POINT"), _of(LIBRARY.test, "POINT") + held_out_waves)
    report, trainer = _train(session, tmp_path / "run")
    assert trainer.trained == ("POINT",)
    assert {clip["behaviour"] for clip in report["held_out"]["clips"]} == {"point"}, "waves are not scored"
    assert (f"note: training point only: wave's {len(held_out_waves)} clips are all held out (split \"test\"): "
            "mark some \"train\" to learn it.") in capsys.readouterr().err


def test_a_library_of_every_behaviour_says_nothing_left_out(tmp_path, capsys):
    _train(_session(LIBRARY.train, LIBRARY.test), tmp_path / "run")
    assert "only:" not in capsys.readouterr().err


def _jump(count):
    """`count` clips of a new target behaviour JUMP (a typo's: each a point clip renamed)."""
    return [replace(make_clip(f"jump_{k}", "POINT", "LEFT", np.array([0.3, -2.0, 1.5]), 40), behaviour="JUMP",
                    kind="target", source=f"clips/jump_{k}.fbx") for k in range(count)]


def test_a_new_behaviour_named_by_one_clip_is_refused_naming_it_and_nothing_is_written(tmp_path):
    session = _session(LIBRARY.train + _jump(1), LIBRARY.test)
    with pytest.raises(RLAnimateError, match=r"^The clip library names a new behaviour in fewer than 3 clips: JUMP by "
                                             r"1 clip \(jump_0\.fbx\)\. If it is a typo, correct the clips' "
                                             r"\"behaviour\" in the manifest; to learn it .* --allow-new-behaviour"):
        _train(session, tmp_path / "run")
    assert not (tmp_path / "run").exists(), "a refused run leaves no folder"


def test_a_new_behaviour_of_two_clips_held_out_or_not_is_refused(tmp_path):
    jumps = _jump(2)
    with pytest.raises(RLAnimateError, match=r"JUMP by 2 clips \(jump_0\.fbx, jump_1\.fbx\)"):
        _train(_session(LIBRARY.train + jumps[:1], LIBRARY.test + jumps[1:]), tmp_path / "run")


@pytest.mark.parametrize("values", [dict(allow_new_behaviour=True), dict(behaviour="point,jump")])
def test_a_new_behaviour_of_few_clips_trains_when_asked_for(tmp_path, values):
    _, trainer = _train(_session(LIBRARY.train + _jump(1), LIBRARY.test), tmp_path / "run", **values)
    assert "JUMP" in trainer.trained


def test_a_new_behaviour_of_three_clips_trains(tmp_path):
    _, trainer = _train(_session(LIBRARY.train + _jump(3), LIBRARY.test), tmp_path / "run")
    assert trainer.trained == ("POINT", "WAVE", "JUMP")
