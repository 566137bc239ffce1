"""A library whose every clip is "train" (a user's own library rarely has splits) trains to an agent: the run
says up front that it has no held-out clips, scores on the training clips, writes agent.npz and its report,
and resumes."""
import json
from types import SimpleNamespace

import pytest

from rlanimate_addon.core import runtime
from tests.trainer.synthetic_library import make_library
from trainer.experiments.run import RunSettings, train
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment


@pytest.fixture(scope="module")
def session():
    env = NumpyFKEnvironment()
    library = make_library(seed=5)
    return SimpleNamespace(env=env, references=ClipReferences(env), train_clips=library.train + library.test,
                           test_clips=[], problems=[])


@pytest.mark.parametrize("eval_every", [0, 1])
def test_a_library_without_held_out_clips_trains_to_an_agent(session, tmp_path, capsys, eval_every):
    output = tmp_path / "run"
    settings = RunSettings(output=str(output), preset="debug", epochs=2, eval_every=eval_every, seed=1,
                           progress=False)
    report, trainer = train(settings, session)
    assert "note: the library has no held-out point or wave clips (split \"test\")" in capsys.readouterr().err
    assert trainer.epoch == 2 and report["held_out"] is None
    assert len(report["training"]["clips"]) == 10  # SEEN_CLIP_COUNT of the 12 training clips
    agent = runtime.load_agent(output / "agent.npz")
    assert set(agent.average_frames) == {"POINT", "WAVE"}
    assert json.loads((output / "report.json").read_text())["held_out"] is None
    assert "| held-out (unseen) | 0 |" in (output / "report.md").read_text()
    metrics = [json.loads(line) for line in (output / "metrics.jsonl").read_text().splitlines()]
    assert "seen/score" in metrics[-1] and "unseen/score" not in metrics[-1]

    (output / "agent.npz").unlink()
    report, trainer = train(RunSettings(output=str(output), epochs=3, resume=True, progress=False), session)
    assert trainer.epoch == 3 and (output / "agent.npz").stat().st_size > 0, "--resume finishes and writes the agent"
