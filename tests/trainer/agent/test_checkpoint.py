"""Checkpoints: atomic, plain data, clear errors; and a resumed run equals the uninterrupted one bit for bit."""
import argparse
import dataclasses
import json
import random
import re
import shutil
from types import SimpleNamespace

import numpy as np
import pytest
import torch

from rlanimate_addon.core.errors import RLAnimateError
from tests.trainer.synthetic_library import make_library
from trainer.agent import checkpoint
from trainer.agent.algorithm import Trainer
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent
from trainer.experiments.run import RunSettings, train
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment

torch.set_num_threads(1)


def test_save_is_atomic_and_loads_as_plain_data(tmp_path):
    path = tmp_path / "run" / checkpoint.FILENAME
    checkpoint.save(path, {"epoch": 3, "weights": torch.arange(5.0)}, {"seed": 1})
    checkpoint.save(path, {"epoch": 4, "weights": torch.arange(6.0)}, {"seed": 1})  # replaces in place
    assert [p.name for p in path.parent.iterdir()] == [checkpoint.FILENAME]  # no temporary left behind
    payload = checkpoint.load(path)
    assert payload["trainer"]["epoch"] == 4 and torch.equal(payload["trainer"]["weights"], torch.arange(6.0))
    assert payload["arguments"] == {"seed": 1}


def test_rng_states_round_trip():
    numpy_rng, torch_rng = np.random.default_rng(4), torch.Generator().manual_seed(4)
    random.seed(9)
    torch.manual_seed(9)
    states = checkpoint.capture_rng_states(numpy_rng, torch_rng)
    first = (random.random(), numpy_rng.random(), torch.rand(2), torch.rand(2, generator=torch_rng))
    checkpoint.restore_rng_states(states, numpy_rng, torch_rng)
    second = (random.random(), numpy_rng.random(), torch.rand(2), torch.rand(2, generator=torch_rng))
    assert first[:2] == second[:2] and torch.equal(first[2], second[2]) and torch.equal(first[3], second[3])


def test_missing_damaged_and_foreign_checkpoints_raise_clear_errors(tmp_path):
    with pytest.raises(RLAnimateError, match="No checkpoint"):
        checkpoint.load(tmp_path / "absent.pt")
    damaged = tmp_path / "damaged.pt"
    checkpoint.save(damaged, {"epoch": 1, "weights": torch.zeros(1000)}, {})
    damaged.write_bytes(damaged.read_bytes()[:300])
    with pytest.raises(RLAnimateError, match="damaged"):
        checkpoint.load(damaged)
    foreign = tmp_path / "foreign.pt"
    torch.save({"format_version": 99}, foreign)
    with pytest.raises(RLAnimateError, match="format version"):
        checkpoint.load(foreign)


def test_a_checkpoint_holding_code_is_refused_without_torchs_advice_to_unpickle_it(tmp_path):
    path = tmp_path / checkpoint.FILENAME
    torch.save({"format_version": checkpoint.FORMAT_VERSION, "arguments": argparse.Namespace(seed=1)}, path)
    with pytest.raises(RLAnimateError) as refused:
        checkpoint.load(path)
    message = str(refused.value)
    assert message.startswith(f"The checkpoint {path} is damaged (Unsupported global: GLOBAL argparse.Namespace")
    assert message.endswith("train.py with --overwrite (which replaces it) or another --output folder; an "
                            "experiment after moving the run's folder away."), "the advice keeps the run's files"
    assert "weights_only" not in message and "\x1b" not in message


@pytest.fixture(scope="module")
def session():
    env = NumpyFKEnvironment()
    library = make_library(seed=5)
    return SimpleNamespace(env=env, references=ClipReferences(env), train_clips=library.train,
                           test_clips=library.test, problems=["clips/wave_left_009.fbx: the file is corrupt"])


def _run(session, output, epochs, resume=False):
    settings = RunSettings(output=str(output), preset="debug", epochs=epochs, eval_every=2, seed=3, resume=resume,
                           progress=False)
    return train(settings, session)


def test_resumed_run_equals_the_uninterrupted_run(session, tmp_path):
    """Resumed twice: what a resumed run saves (the dicts `load` returned among them) loads again."""
    _, straight = _run(session, tmp_path / "straight", 4)
    _, first_half = _run(session, tmp_path / "resumed", 2)
    _, once = _run(session, tmp_path / "resumed", 3, resume=True)
    _, resumed = _run(session, tmp_path / "resumed", 4, resume=True)
    assert (first_half.epoch, once.epoch, resumed.epoch) == (2, 3, 4)
    a, b = straight.state_dict(), resumed.state_dict()
    assert a["agent"].keys() == b["agent"].keys()
    assert all(torch.equal(a["agent"][k], b["agent"][k]) for k in a["agent"])
    for state_a, state_b in zip(a["optimizer"]["state"].values(), b["optimizer"]["state"].values(), strict=True):
        assert all(torch.equal(state_a[k], state_b[k]) for k in state_a)
    assert len(straight.buffer) == len(resumed.buffer)
    assert all(
        np.array_equal(x[k], y[k])
        for x, y in zip(straight.buffer.episodes, resumed.buffer.episodes, strict=True)
        for k in x
    )
    assert [e["loss/total"] for e in a["history"]] == [e["loss/total"] for e in b["history"]]
    lines = (tmp_path / "resumed" / "metrics.jsonl").read_text().splitlines()
    assert len(lines) == 4  # the metrics log is rebuilt from the checkpoint, not duplicated
    report = json.loads((tmp_path / "resumed" / "report.json").read_text())
    assert report["skipped_clips"] == session.problems, "clips that did not import are in report.json"


def test_a_run_killed_mid_schedule_resumes_exactly(session, tmp_path):
    """Kill after 2 of 4 planned epochs (learning rate mid-decay), rebuild from the file, continue."""
    agent_config, train_config = load_preset("debug")
    train_config = dataclasses.replace(train_config, learning_rate=3e-3, learning_rate_final=1e-4,
                                       random_targets=2, random_target_weight=0.5)  # weighted chunk draws too

    def fresh_trainer():
        torch.manual_seed(0)
        return Trainer(RLAnimateAgent(agent_config), session.env, session.train_clips, train_config, "both",
                       seed=8, references=session.references, epochs=4)

    straight = fresh_trainer()
    for _ in range(4):
        straight.run_epoch()
    killed = fresh_trainer()
    for _ in range(2):
        killed.run_epoch()
    checkpoint.save(tmp_path / checkpoint.FILENAME, killed.state_dict(), {})
    torch.manual_seed(123)  # the new process's RNGs are whatever they are
    resumed = fresh_trainer()
    resumed.load_state_dict(checkpoint.load(tmp_path / checkpoint.FILENAME)["trainer"])
    for _ in range(2):
        resumed.run_epoch()
    assert [e["learning_rate"] for e in resumed.history] == [e["learning_rate"] for e in straight.history]
    assert resumed.history[1]["learning_rate"] < train_config.learning_rate  # the schedule was decaying
    a, b = straight.agent.state_dict(), resumed.agent.state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)


@pytest.fixture(scope="module")
def two_epoch_run(session, tmp_path_factory):
    folder = tmp_path_factory.mktemp("two_epochs") / "run"
    _run(session, folder, 2)
    return folder


@pytest.mark.parametrize("missing", ["trainer.rng", "trainer.buffer", "trainer.rng.numpy", "arguments.clips",
                                     "trainer"])
def test_a_checkpoint_missing_a_key_is_refused_naming_it_and_the_run_is_kept(session, two_epoch_run, tmp_path,
                                                                             missing):
    run = tmp_path / "run"
    shutil.copytree(two_epoch_run, run)
    path = run / checkpoint.FILENAME
    payload = torch.load(path, weights_only=True)
    *parents, key = missing.split(".")
    parent = payload
    for name in parents:
        parent = parent[name]
    del parent[key]
    torch.save(payload, path)
    files = {p.name: p.read_bytes() for p in run.iterdir() if p.is_file()}
    with pytest.raises(RLAnimateError, match=rf"^The checkpoint {re.escape(str(path))} lacks {re.escape(missing)}: "
                                             r"it is incomplete.*train the run again: train.py with --overwrite"):
        _run(session, run, 4, resume=True)
    assert {p.name: p.read_bytes() for p in run.iterdir() if p.is_file()} == files, "the run's files are kept"


def test_a_checkpoint_an_earlier_trainer_wrote_after_a_resume_loads_and_the_run_finishes(session, two_epoch_run,
                                                                                        tmp_path):
    """Before issue 44 a resumed run saved the dicts `load` had returned as they were (_CheckedDicts, holding
    the checkpoint's PosixPath), which weights_only refuses: such a file loads, as plain data."""
    run = tmp_path / "run"
    shutil.copytree(two_epoch_run, run)
    path = run / checkpoint.FILENAME
    payload = checkpoint.load(path)
    assert type(payload["trainer"]["history"][0]) is checkpoint._CheckedDict
    torch.save({"format_version": checkpoint.FORMAT_VERSION, "arguments": payload["arguments"],
                "trainer": payload["trainer"]}, path)  # what the earlier save wrote
    with pytest.raises(Exception, match="_CheckedDict"):
        torch.load(path, weights_only=True)
    loaded = checkpoint.load(path)
    assert loaded["trainer"]["history"][1]["loss/total"] == payload["trainer"]["history"][1]["loss/total"]
    _, resumed = _run(session, run, 4, resume=True)
    _, straight = _run(session, tmp_path / "straight", 4)
    a, b = straight.agent.state_dict(), resumed.agent.state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)
    torch.load(path, weights_only=True)  # what this trainer writes is plain data
