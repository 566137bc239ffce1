"""Evaluation: clip selection, score/smoothness of rollouts against the clips' own FK, length flexibility."""
import numpy as np
import pytest
import torch

from rlanimate_addon.core import metrics, spaces
from tests.trainer.synthetic_library import make_library
from trainer.agent.algorithm import clip_objective
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent
from trainer.evaluation import scoring
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment

torch.set_num_threads(1)


class ReplayAgent(torch.nn.Module):
    """Answers each clip's objectives with the clip's own motion, plus optional per-frame noise."""

    space = spaces.PAPER_SPACE

    def __init__(self, clips, noise=0.0):
        super().__init__()
        rng = np.random.default_rng(0)
        self.motions = []  # (objectives (N, O) float32, motion (N, 45)) per clip
        for clip in clips:
            objective = torch.as_tensor(clip_objective(spaces.PAPER_SPACE, clip), dtype=torch.float32)
            motion = spaces.encode_action(clip.rotvecs)
            self.motions.append((objective, np.clip(motion + noise * rng.standard_normal(motion.shape), 0, 1)))

    def rollout(self, objectives, deterministic=True, generator=None):
        """(B, T, O) objectives, each a clip's padded at its end -> (B, T, 45): the clip's motion, padded alike."""
        answers = []
        for row in objectives:
            motion = next(m for o, m in self.motions if len(o) <= len(row) and torch.equal(o, row[:len(o)]))
            answers.append(np.concatenate([motion, np.repeat(motion[-1:], len(row) - len(motion), 0)]))
        return torch.as_tensor(np.stack(answers))


@pytest.fixture(scope="module")
def env():
    return NumpyFKEnvironment()


@pytest.fixture(scope="module")
def library():
    return make_library(seed=2, per_behaviour=5)


def test_select_clips_spreads_and_balances(library):
    assert scoring.select_clips(library.test, ("POINT",)) == [c for c in library.test if c.behaviour == "POINT"]
    chosen = scoring.select_clips(library.train, ("POINT", "WAVE"), 5)
    assert [c.behaviour for c in chosen].count("POINT") == 3 and len(chosen) == 5
    points = [c for c in library.train if c.behaviour == "POINT"]
    assert scoring.select_clips(library.train, ("POINT",), 2) == [points[0], points[-1]]


def test_a_replayed_clip_scores_100_and_noise_lowers_score_and_smoothness(env, library):
    clips = library.test
    references = ClipReferences(env)
    perfect = scoring.evaluate_clips(ReplayAgent(clips), env, clips, references)
    assert perfect["score"] == pytest.approx(100.0, abs=1e-3)
    reference_smoothness = np.mean([metrics.smoothness(references.get(c)[1]) for c in clips])
    assert perfect["smoothness"] == pytest.approx(reference_smoothness, abs=1e-3)
    assert [row["name"] for row in perfect["clips"]] == [c.name for c in clips]
    waves = [row["score"] for row in perfect["clips"] if row["behaviour"] == "wave"]
    assert perfect["by_behaviour"]["wave"]["score"] == pytest.approx(np.mean(waves))
    for row in perfect["clips"]:  # the behaviour measures sit beside the score: a replay matches them all
        assert row["aligned_score"] == pytest.approx(100.0, abs=1e-3)
        assert row["elevation_first_error"] < 1e-3 and row["elevation_last_error"] < 1e-3
        assert row["behaviour"] == "point" or row["swing_ratio"] == pytest.approx(1.0, abs=1e-3)
    noisy = scoring.evaluate_clips(ReplayAgent(clips, noise=0.03), env, clips, references)
    assert noisy["score"] < perfect["score"] - 0.5
    assert noisy["smoothness"] < perfect["smoothness"] - 0.5


def test_length_flexibility_rolls_out_each_scaled_length(env, library):
    agent_config, _ = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(agent_config, "rlanimate")
    scales = (0.4, 1.0, 1.5)
    result = scoring.length_flexibility(agent, env, library.test, library.train, scales)
    assert set(result) == {"point", "wave"}
    for by_scale in result.values():
        assert list(by_scale) == ["0.4", "1", "1.5"]
        assert all(0.0 <= value <= 100.0 for value in by_scale.values())
    waves = [c for c in library.test if c.behaviour == "WAVE"]
    mean_length = np.mean([len(c.rotvecs) for c in library.train if c.behaviour == "WAVE"])
    objectives = [clip_objective(spaces.PAPER_SPACE, c, int(round(1.5 * mean_length))) for c in waves]
    positions = [spaces.description_joint_positions(d) for d in scoring.generate_descriptions(agent, env, objectives)]
    assert [len(p) for p in positions] == [int(round(1.5 * mean_length))] * len(waves)
    assert result["wave"]["1.5"] == pytest.approx(np.mean([metrics.smoothness(p) for p in positions]))
