"""A run's folder: a new run into the folder of a finished or stopped run is refused before anything is
written unless --overwrite (which replaces that run's files, and only those); --resume and --overwrite
together are refused; a refused run leaves no empty folder."""
from types import SimpleNamespace

import pytest

from rlanimate_addon.core.errors import RLAnimateError
from tests.trainer.synthetic_library import make_library
from trainer.agent import checkpoint
from trainer.experiments.run import RunSettings, train
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment
from trainer.scripts import cli
from trainer.scripts import train as train_script

ENV = NumpyFKEnvironment()
LIBRARY = make_library(seed=5)
SESSION = SimpleNamespace(env=ENV, references=ClipReferences(ENV), train_clips=LIBRARY.train,
                          test_clips=LIBRARY.test, problems=[])


def _train(output, **values):
    settings = {"preset": "debug", "epochs": 1, "seed": 1, "eval_every": 0, "progress": False, **values}
    return train(RunSettings(output=str(output), **settings), SESSION)


def _files(folder):
    return {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    folder = tmp_path_factory.mktemp("finished") / "run"
    _train(folder)
    (folder / "notes.txt").write_text("the user's own file")
    return folder


def test_a_new_run_into_a_finished_runs_folder_is_refused_and_nothing_changes(finished):
    before = _files(finished)
    with pytest.raises(RLAnimateError, match=rf"--output {finished} holds a finished run \(its agent.npz\): choose "
                                             r"another --output, or add --overwrite to replace that run\. Nothing was "
                                             r"trained\."):
        _train(finished, seed=2)
    assert _files(finished) == before


def test_a_new_run_into_a_stopped_runs_folder_is_refused_pointing_at_resume(finished, tmp_path):
    stopped = tmp_path / "run"
    stopped.mkdir()
    (stopped / checkpoint.FILENAME).write_bytes((finished / checkpoint.FILENAME).read_bytes())
    with pytest.raises(RLAnimateError, match=r"holds a run that has not finished \(its checkpoint.pt\): continue it "
                                             r"with --resume, or add --overwrite to replace it"):
        _train(stopped)


def test_overwrite_replaces_the_runs_files_and_keeps_the_others(finished, tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    for path, data in _files(finished).items():
        (folder / path).parent.mkdir(parents=True, exist_ok=True)
        (folder / path).write_bytes(data)
    (folder / "tensorboard").mkdir(exist_ok=True)
    (folder / "tensorboard" / "events.old").write_text("the old run's curves")
    report, _ = _train(folder, seed=2, overwrite=True)
    assert report["seed"] == 2
    assert (folder / "agent.npz").read_bytes() != (finished / "agent.npz").read_bytes()
    assert not (folder / "tensorboard" / "events.old").exists(), "the old run's curves do not mix with the new"
    assert (folder / "notes.txt").read_text() == "the user's own file", "only the run's own files are replaced"


def test_resume_with_overwrite_is_refused(finished):
    with pytest.raises(RLAnimateError, match=r"--resume and --overwrite: give one"):
        _train(finished, resume=True, overwrite=True)


def test_a_run_refused_after_the_clips_loaded_leaves_no_folder(tmp_path):
    with pytest.raises(RLAnimateError, match="The clip library has no beckon training clips"):
        _train(tmp_path / "new" / "run", behaviour="beckon")
    assert not (tmp_path / "new").exists()


def test_the_script_refuses_a_finished_runs_folder_in_one_line_before_importing_clips(finished, monkeypatch,
                                                                                      capsys):
    def no_import(*args, **kwargs):
        raise AssertionError("the clips were imported before --output was checked")

    monkeypatch.setattr(train_script, "LibrarySession", no_import)
    argv = ["train.py", "--preset", "debug", "--output", str(finished)]
    assert cli.run_main(train_script.main, argv) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"error: --output {finished} holds a finished run") and error.count("\n") == 1
