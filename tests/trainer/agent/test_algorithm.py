"""Algorithm 1: the episode buffer's chunks, one iteration's collection, and a debug run whose loss falls."""
from dataclasses import replace

import numpy as np
import pytest
import torch

from rlanimate_addon.core import spaces
from tests.trainer.synthetic_library import make_library
from trainer.agent import checkpoint, pointing
from trainer.agent.algorithm import (
    Trainer,
    chunks_per_update,
    clip_objective,
    clips_for_behaviour,
    epoch_updates,
    rollout_actions,
)
from trainer.agent.buffer import EPISODE_KEYS, FIRST_FRAME_SHARE, EpisodeBuffer
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent
from trainer.motion.clip import library_space
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment

torch.set_num_threads(1)


def _episode(frames, offset):
    """Episode whose every value encodes its frame index + offset, so chunks reveal where they came from."""
    stamp = (np.arange(frames) + offset).astype(np.float64)[:, None]
    sizes = {"objective": 7, "action": 45, "description": 42, "motion": 45, "motion_description": 42}
    episode = {key: np.repeat(stamp, sizes[key], axis=1) for key in sizes}
    return {**episode, "hold": stamp[:, 0], "imitate": stamp[:, 0]}


def test_chunks_are_contiguous_slices_of_one_episode_and_reproducible():
    buffer = EpisodeBuffer()
    buffer.add(_episode(30, 0))
    buffer.add(_episode(40, 1000))
    chunks = buffer.sample_chunks(16, 10, np.random.default_rng(7))
    assert chunks["action"].shape == (16, 10, 45) and chunks["description"].shape == (16, 10, 42)
    stamps = chunks["objective"][:, :, 0].numpy()  # (C, L)
    assert np.all(np.diff(stamps, axis=1) == 1)  # consecutive frames of one episode
    assert all(np.all(chunks[key].reshape(16, 10, -1)[:, :, 0].numpy() == stamps) for key in EPISODE_KEYS)  # aligned
    assert {bool(s[0] >= 1000) for s in stamps} == {False, True}  # both episodes drawn
    again = buffer.sample_chunks(16, 10, np.random.default_rng(7))
    assert torch.equal(again["objective"], chunks["objective"])


def test_a_share_of_chunks_starts_at_the_first_frame():
    buffer = EpisodeBuffer()
    buffer.add(_episode(200, 0))
    starts = buffer.sample_chunks(2000, 10, np.random.default_rng(3))["objective"][:, 0, 0].numpy()
    uniform = (1.0 - FIRST_FRAME_SHARE) / 191
    assert abs(np.mean(starts == 0) - (FIRST_FRAME_SHARE + uniform)) < 0.03
    assert len(np.unique(starts)) > 150  # the others anywhere


def test_a_share_of_chunks_ends_at_the_last_frame():
    buffer = EpisodeBuffer()
    buffer.add(_episode(200, 0))
    starts = buffer.sample_chunks(2000, 10, np.random.default_rng(3), last_frame_share=0.25)["objective"][:, 0, 0]
    uniform = (1.0 - FIRST_FRAME_SHARE - 0.25) / 191
    assert abs(np.mean(starts.numpy() == 190) - (0.25 + uniform)) < 0.03
    assert abs(np.mean(starts.numpy() == 0) - (FIRST_FRAME_SHARE + uniform)) < 0.03


def test_random_target_episodes_are_drawn_at_their_weight():
    buffer = EpisodeBuffer()
    for k in range(6):
        episode = _episode(20, 1000 * k)
        episode["imitate"] = np.full(20, float(k < 3))  # three clip episodes, then three random-target ones
        buffer.add(episode)
    for weight, share in ((1.0, 0.5), (1 / 3, 0.25)):
        firsts = buffer.sample_chunks(4000, 5, np.random.default_rng(2), weight)["objective"][:, 0, 0].numpy()
        assert abs(np.mean(firsts >= 3000) - share) < 0.03


def test_chunk_length_is_capped_at_the_shortest_episode():
    buffer = EpisodeBuffer()
    buffer.add(_episode(12, 0))
    buffer.add(_episode(50, 100))
    assert buffer.sample_chunks(3, 40, np.random.default_rng(0))["motion"].shape == (3, 12, 45)


def test_episodes_with_mismatched_lengths_are_rejected():
    episode = _episode(10, 0)
    episode["action"] = episode["action"][:9]
    with pytest.raises(ValueError, match="frame count"):
        EpisodeBuffer().add(episode)


@pytest.fixture(scope="module")
def env():
    return NumpyFKEnvironment()


@pytest.fixture(scope="module")
def library():
    return make_library(seed=3)


def test_training_both_draws_one_clip_per_behaviour(library):
    groups = clips_for_behaviour(library.train, "both", spaces.PAPER_SPACE)
    assert [{c.behaviour for c in g} for g in groups] == [{"POINT"}, {"WAVE"}]
    assert len(clips_for_behaviour(library.train, "wave", spaces.PAPER_SPACE)) == 1
    assert len(clips_for_behaviour(library.train, "all", spaces.PAPER_SPACE)) == 2


def test_collect_stores_real_descriptions_and_clip_motion(env, library):
    agent_config, train_config = load_preset("debug")
    torch.manual_seed(0)
    trainer = Trainer(RLAnimateAgent(agent_config, "rlanimate"), env, library.train, train_config, "both", seed=1)
    drawn = trainer.collect()
    assert len(trainer.buffer) == 2 + train_config.random_targets
    assert [c.behaviour for c in drawn] == ["POINT", "WAVE"] + ["POINT"] * train_config.random_targets
    for k, (clip, episode) in enumerate(zip(drawn, trainer.buffer.episodes, strict=True)):
        imitated = k < 2
        assert np.all(episode["imitate"] == float(imitated))
        if imitated:
            np.testing.assert_allclose(episode["objective"], clip_objective(spaces.PAPER_SPACE, clip), atol=1e-6)
        else:  # a random target, timed like the clip
            assert len(episode["objective"]) == len(clip.rotvecs) and np.all(episode["objective"][:, 0] == 1.0)
            direction = episode["objective"][0, 3:6]
            assert np.isclose(np.linalg.norm(direction), 1.0, atol=1e-6)
            assert not np.allclose(direction, clip.attributes, atol=1e-3)
        np.testing.assert_allclose(episode["motion"], spaces.encode_action(clip.rotvecs), atol=1e-6)
        real = env.evaluate(spaces.decode_action(episode["action"].astype(np.float64))).descriptions
        np.testing.assert_allclose(episode["description"], real, atol=1e-4)
        reference = env.evaluate(clip.rotvecs).descriptions
        np.testing.assert_allclose(episode["motion_description"], reference, atol=1e-5)
        assert np.all((episode["action"] >= 0) & (episode["action"] <= 1))


def _four_behaviours(library):
    """The library plus GUIDE (a target behaviour, its clips pointing to the side, away from the points)
    and RAISE (an intensity behaviour): relabelled point and wave clips."""
    def relabel(clip, behaviour, kind, attributes):
        return replace(clip, name=clip.name.replace(clip.behaviour.lower(), behaviour.lower()),
                       behaviour=behaviour, kind=kind, attributes=attributes)
    side = {"LEFT": np.array([1.0, 0.0, 0.0]), "RIGHT": np.array([-1.0, 0.0, 0.0])}
    guides = [relabel(c, "GUIDE", "target", side[c.arm]) for c in library.train if c.behaviour == "POINT"]
    raises = [relabel(c, "RAISE", "intensity", c.attributes) for c in library.train if c.behaviour == "WAVE"]
    return library.train + guides + raises


def test_every_behaviour_keeps_the_chunks_and_random_targets_it_has_beside_one_other(env, library):
    assert [chunks_per_update(32, n) for n in (1, 2, 3, 4)] == [32, 32, 48, 64]
    clips = _four_behaviours(library)
    agent_config, train_config = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(agent_config, "rlanimate", library_space(clips))
    trainer = Trainer(agent, env, clips, replace(train_config, random_targets=3), "all", seed=1)
    assert trainer.chunk_count == 2 * train_config.chunk_count
    drawn = trainer.collect()
    assert [c.behaviour for c in drawn] == ["POINT", "WAVE", "GUIDE", "RAISE"] + ["POINT"] * 3 + ["GUIDE"] * 3
    for clip, episode in zip(
        drawn[4:], trainer.buffer.episodes[4:], strict=True
    ):  # each within its own behaviour's range
        direction = episode["objective"][0, spaces.OBJECTIVE_ATTRIBUTES]
        side = 1.0 if clip.arm == "LEFT" else -1.0
        if clip.behaviour == "GUIDE":  # the guides' range: straight to the arm's side, widened by the margin
            assert side * direction[0] > 0.7
        else:  # the points': ahead
            assert direction[1] < -0.3


def test_more_than_two_behaviours_make_fewer_update_steps(env, library):
    default = load_preset("default")[1]
    assert [epoch_updates(default, n) for n in (1, 2, 3, 4)] == [(120, 32), (120, 32), (99, 48), (99, 48)]
    unset = replace(default, update_steps_many=None, chunk_count_many=None)
    assert [epoch_updates(unset, n) for n in (2, 4)] == [(120, 32), (120, 64)]
    agent_config, train_config = load_preset("debug")
    clips = _four_behaviours(library)
    agent = RLAnimateAgent(agent_config, "rlanimate", library_space(clips))
    trainer = Trainer(agent, env, clips, replace(train_config, update_steps_many=2, chunk_count_many=5), "all", seed=1)
    steps = []
    trainer.optimizer.step = lambda: steps.append(1)  # count the update steps of an epoch
    trainer.run_epoch()
    assert trainer.update_steps == 2 and len(steps) == 2 and trainer.chunk_count == 5
    pair = Trainer(RLAnimateAgent(agent_config), env, library.train, replace(train_config, update_steps_many=2), "both")
    assert (pair.update_steps, pair.chunk_count) == (3, train_config.chunk_count)


def test_a_batched_rollout_is_each_episodes_own_rollout(library):
    torch.manual_seed(0)
    agent = RLAnimateAgent(load_preset("debug")[0])
    objectives = [clip_objective(spaces.PAPER_SPACE, clip) for clip in library.train[:4]]
    assert len({len(o) for o in objectives}) > 1  # padded to the longest
    batched = rollout_actions(agent, objectives)
    for objective, actions in zip(objectives, batched, strict=True):
        assert actions.shape == (len(objective), spaces.ACTION_SIZE)
        assert np.allclose(actions, rollout_actions(agent, [objective])[0], atol=1e-6)
    sampled = [rollout_actions(agent, objectives, deterministic=False, generator=torch.Generator().manual_seed(3))
               for _ in range(2)]
    assert all(np.array_equal(a, b) for a, b in zip(*sampled, strict=True))  # reproducible from the generator


def test_debug_preset_trains_end_to_end_and_its_loss_falls(env, library):
    agent_config, train_config = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(agent_config, "rlanimate")
    trainer = Trainer(agent, env, library.train, train_config, "both", seed=0, references=ClipReferences(env))
    trainer.collect()
    probe = trainer.buffer.sample_chunks(8, train_config.chunk_length, np.random.default_rng(5))

    def probe_loss():
        torch.manual_seed(11)  # the same posterior samples before and after training
        with torch.no_grad():
            return float(agent.losses(probe, train_config)["total"])

    before = probe_loss()
    for _ in range(15):
        metrics = trainer.run_epoch()
    assert metrics["epoch"] == 15 and metrics["episodes"] == (1 + 15) * (2 + train_config.random_targets)
    assert all(np.isfinite(v) for k, v in metrics.items() if k.startswith("loss/"))
    assert probe_loss() < 0.8 * before


def test_clips_are_drawn_in_passes_without_replacement(env, library):
    agent_config, train_config = load_preset("debug")
    trainer = Trainer(RLAnimateAgent(agent_config, "rlanimate"), env, library.train, train_config, "wave", seed=4)
    waves = trainer.clip_groups[0]
    drawn = [id(trainer.draw(0)) for _ in range(2 * len(waves))]
    assert sorted(drawn[:len(waves)]) == sorted(id(clip) for clip in waves)  # each clip once per pass
    assert sorted(drawn[len(waves):]) == sorted(drawn[:len(waves)]) and drawn[len(waves):] != drawn[:len(waves)]


@pytest.mark.parametrize("margin", [0.0, 10.0])
def test_random_targets_cover_the_clips_range_widened_by_the_margin(env, library, margin):
    agent_config, train_config = load_preset("debug")
    train_config = replace(train_config, random_target_margin_deg=margin)
    trainer = Trainer(RLAnimateAgent(agent_config, "rlanimate"), env, library.train, train_config, "point", seed=2)
    clips = [np.degrees(pointing.azimuth_elevation("LEFT", c.attributes)) for c in trainer.clip_groups[0]
             if c.arm.upper() == "LEFT"]
    drawn = np.degrees([pointing.azimuth_elevation("LEFT", trainer._random_direction(trainer.clip_groups[0], "LEFT"))
                       for _ in range(400)])
    low, high = np.min(clips, axis=0) - margin, np.max(clips, axis=0) + margin
    assert np.all(drawn >= low - 1e-9) and np.all(drawn <= high + 1e-9)
    reach = margin / 2 if margin else -0.1 * (high - low)  # the draws use the margin, or fill the range
    assert np.all(drawn.min(axis=0) < low + margin - reach) and np.all(drawn.max(axis=0) > high - margin + reach)


def test_averaging_plays_the_mean_of_the_last_epochs_weights_and_resumes_exactly(env, library, tmp_path):
    agent_config, train_config = load_preset("debug")
    train_config = replace(train_config, average_last_epochs=2)

    def trainer():
        torch.manual_seed(0)
        return Trainer(RLAnimateAgent(agent_config, "rlanimate"), env, library.train, train_config, "both", seed=0,
                       epochs=4)

    run = trainer()
    snapshots = []
    for _ in range(4):
        run.run_epoch()
        snapshots.append({name: value.clone() for name, value in run.agent.state_dict().items()})
        assert (run.played_agent is run.agent) == (run.epoch <= 2)
    for name, value in run.played_agent.state_dict().items():
        torch.testing.assert_close(value, (snapshots[2][name] + snapshots[3][name]) / 2)
    resumed = trainer()
    first = trainer()
    for _ in range(3):
        first.run_epoch()
    checkpoint.save(tmp_path / "checkpoint.pt", first.state_dict(), {})  # loads with weights_only
    resumed.load_state_dict(checkpoint.load(tmp_path / "checkpoint.pt")["trainer"])
    resumed.run_epoch()
    for name, value in run.played_agent.state_dict().items():
        assert torch.equal(resumed.played_agent.state_dict()[name], value), name


def test_an_extended_run_averages_its_new_last_epochs_only(env, library, tmp_path):
    agent_config, train_config = load_preset("debug")
    train_config = replace(train_config, average_last_epochs=2)

    def trainer(epochs):
        torch.manual_seed(0)
        return Trainer(RLAnimateAgent(agent_config, "rlanimate"), env, library.train, train_config, "both", seed=0,
                       epochs=epochs)

    planned = trainer(3)
    for _ in range(3):
        planned.run_epoch()
    assert planned.played_agent is not planned.agent  # epochs 2 and 3 averaged
    checkpoint.save(tmp_path / "checkpoint.pt", planned.state_dict(), {})
    extended = trainer(5)
    extended.load_state_dict(checkpoint.load(tmp_path / "checkpoint.pt")["trainer"])
    assert extended.played_agent is extended.agent  # the old window's average is dropped
    snapshots = []
    for _ in range(2):
        extended.run_epoch()
        snapshots.append({name: value.clone() for name, value in extended.agent.state_dict().items()})
    for name, value in extended.played_agent.state_dict().items():
        torch.testing.assert_close(value, (snapshots[0][name] + snapshots[1][name]) / 2)
