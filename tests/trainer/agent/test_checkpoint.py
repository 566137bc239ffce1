"""Checkpoints: atomic, plain data, clear errors; and a resumed run equals the uninterrupted one bit for bit."""
import dataclasses
import json
import random
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
    _, straight = _run(session, tmp_path / "straight", 4)
    _, first_half = _run(session, tmp_path / "resumed", 2)
    _, resumed = _run(session, tmp_path / "resumed", 4, resume=True)
    assert first_half.epoch == 2 and resumed.epoch == 4
    a, b = straight.state_dict(), resumed.state_dict()
    assert a["agent"].keys() == b["agent"].keys()
    assert all(torch.equal(a["agent"][k], b["agent"][k]) for k in a["agent"])
    for state_a, state_b in zip(a["optimizer"]["state"].values(), b["optimizer"]["state"].values()):
        assert all(torch.equal(state_a[k], state_b[k]) for k in state_a)
    assert len(straight.buffer) == len(resumed.buffer)
    assert all(np.array_equal(x[k], y[k]) for x, y in zip(straight.buffer.episodes, resumed.buffer.episodes)
               for k in x)
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
