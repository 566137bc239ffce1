"""The numpy runtime reproduces the torch agent's deterministic rollout, for every variant."""
from dataclasses import replace

import numpy as np
import pytest
import torch

from rlanimate_addon.core import rhythm, spaces
from rlanimate_addon.core import runtime as runtime_module
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.runtime import GestureAgent, load_agent
from trainer.agent.agent_export import export_agent
from trainer.agent.config import load_preset
from trainer.agent.models import VARIANTS, RLAnimateAgent

torch.set_num_threads(1)


RHYTHM = rhythm.RhythmModel.fit([0.0, 0.5, 1.0], [rhythm.Rhythm(0.08, 0.3, 0.7, 0.2, 9.0),
                                                   rhythm.Rhythm(0.075, 0.32, 0.66, -0.4, 9.0),
                                                   rhythm.Rhythm(0.072, 0.33, 0.69, 0.5, 9.0)])


def objectives_for_tests(frames=150):
    point = spaces.PAPER_SPACE.make_objective("POINT", "LEFT", [0.4, -0.8, 0.3], frames)
    wave = spaces.PAPER_SPACE.make_objective("WAVE", "RIGHT", 0.7, frames // 2)
    swinging = spaces.PAPER_SPACE.make_objective(
        "WAVE", "LEFT", 0.3, frames, rhythm.signals(RHYTHM.draw(0.3, 4), frames)
    )
    return [point, wave, swinging]


def exported_agent(tmp_path, preset, variant, weight_gain=2.0, seed=0):
    """An agent with weights scaled up from their initialisation, so its dynamics are far from trivial."""
    torch.manual_seed(seed)
    agent = RLAnimateAgent(load_preset(preset)[0], variant)
    return agent, _exported(agent, tmp_path / f"{preset}_{variant}.npz", weight_gain)


def _exported(agent, path, weight_gain):
    with torch.no_grad():
        for parameter in agent.parameters():
            parameter.mul_(weight_gain)
    export_agent(agent, path, {"average_frames": {"POINT": 80, "WAVE": 95}})
    return path


def torch_rollout(agent, objectives):
    return agent.rollout(torch.as_tensor(objectives, dtype=torch.float32)[None])[0].double().numpy()


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("preset", ["debug", "default"])
def test_deterministic_rollout_matches_torch(tmp_path, preset, variant):
    agent, path = exported_agent(tmp_path, preset, variant)
    runtime = load_agent(path)
    for objectives in objectives_for_tests():
        expected = torch_rollout(agent, objectives)
        actions = runtime.rollout(objectives)
        assert actions.shape == expected.shape
        assert np.abs(actions - expected).max() < 1e-5
        assert expected.std(axis=0).max() > 1e-3  # the actions do change over the gesture


@pytest.mark.parametrize("variant", ["rlanimate", "supervised"])
def test_a_phase_input_agent_plays_as_torch_with_the_waves_phase_beside_its_task_state(tmp_path, variant):
    """With phase_input the wave's phase and second harmonic sit beside the task state (spaces.phase_features, and
    the torch model's own): the runtime plays torch's rollout, the file's shapes carry the 4 more inputs, and a
    point's objectives (no phase) still play."""
    torch.manual_seed(3)
    config = replace(load_preset("default")[0], phase_input=True)
    agent = RLAnimateAgent(config, variant)
    path = _exported(agent, tmp_path / "phase.npz", 2.0)
    runtime = load_agent(path)
    assert agent.behaviour_cell.weight_ih.shape[1] == config.task_size + 4 + config.stochastic_size + 45
    for objectives in objectives_for_tests():
        assert np.abs(runtime.rollout(objectives) - torch_rollout(agent, objectives)).max() < 1e-5
    swinging = objectives_for_tests()[2]
    features = spaces.PAPER_SPACE.phase_features(swinging)
    assert np.allclose(np.hypot(features[:, 2], features[:, 3]), np.hypot(features[:, 0], features[:, 1]))
    assert not spaces.PAPER_SPACE.phase_features(objectives_for_tests()[0]).any(), "a point has no phase"
    with pytest.raises(RLAnimateError, match="needs a task state"):
        RLAnimateAgent(config, "single_state")


@pytest.mark.parametrize("variant", ["rlanimate", "supervised"])
def test_a_tempo_input_agent_plays_as_torch_with_the_swing_rate_beside_the_phase(tmp_path, variant):
    """With tempo_input the wave's swing rate (rhythm.swing_rate: 2 pi x its cycles a frame while the hand swings,
    0 before and after) is a fifth phase feature: the runtime plays torch's rollout, and tempo_input alone is
    refused."""
    torch.manual_seed(4)
    config = replace(load_preset("default")[0], phase_input=True, tempo_input=True)
    agent = RLAnimateAgent(config, variant)
    runtime = load_agent(_exported(agent, tmp_path / "tempo.npz", 2.0))
    assert agent.behaviour_cell.weight_ih.shape[1] == config.task_size + 5 + config.stochastic_size + 45
    for objectives in objectives_for_tests():
        assert np.abs(runtime.rollout(objectives) - torch_rollout(agent, objectives)).max() < 1e-5
    swinging = objectives_for_tests()[2]
    drawn = RHYTHM.draw(0.3, 4)
    rate = spaces.PAPER_SPACE.phase_features(swinging, tempo=True)[:, 4]
    signals = rhythm.signals(drawn, len(swinging))
    moving = np.hypot(signals[:, 0], signals[:, 1]) > 0
    assert np.allclose(rate[moving], 2 * np.pi * drawn.frequency) and not rate[~moving].any()
    assert moving.sum() < len(moving), "the rhythm starts and ends still"
    torch_rate = agent.phase_features(torch.as_tensor(swinging, dtype=torch.float32)[None])[0, :, 4].numpy()
    assert np.allclose(torch_rate, rate, atol=1e-5)
    with pytest.raises(RLAnimateError, match="tempo_input needs phase_input"):
        RLAnimateAgent(replace(config, phase_input=False), variant)


@pytest.mark.parametrize("variant", VARIANTS)
def test_in_float64_the_rollout_is_torchs_to_rounding(tmp_path, variant):
    """The in-place per-frame loop (joined weights, halved gates, scratch arrays) computes torch's equations:
    against the torch agent in float64 it differs by rounding only, where float32 torch allows 1e-5."""
    agent, path = exported_agent(tmp_path, "default", variant)
    runtime, agent = load_agent(path), agent.double()
    for objectives in objectives_for_tests():
        expected = agent.rollout(torch.as_tensor(objectives, dtype=torch.float64)[None])[0].numpy()
        assert np.abs(runtime.rollout(objectives) - expected).max() < 1e-12


def test_rollout_is_a_pure_function_of_the_objectives(tmp_path):
    _, path = exported_agent(tmp_path, "debug", "rlanimate")
    runtime = load_agent(path)
    objectives = objectives_for_tests()[0]
    first = runtime.rollout(objectives)
    runtime.rollout(objectives_for_tests()[1])
    np.testing.assert_array_equal(runtime.rollout(objectives), first)


def test_the_rollout_runs_numpy_blas_on_one_thread_and_restores_the_setting(tmp_path, monkeypatch):
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def blas_threads():
        return {info["num_threads"] for info in threadpoolctl.threadpool_info() if info["user_api"] == "blas"}

    assert blas_threads(), "numpy should load a BLAS library threadpoolctl can see"
    runtime = load_agent(exported_agent(tmp_path, "debug", "rlanimate")[1])
    seen = []
    mlp_tail = runtime_module._mlp_tail
    monkeypatch.setattr(runtime_module, "_mlp_tail", lambda *args: seen.append(blas_threads()) or mlp_tail(*args))
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        runtime.rollout(objectives_for_tests()[0])
        assert blas_threads() == {2}, "the user's BLAS setting must be restored"
    assert seen and all(threads == {1} for threads in seen)


@pytest.mark.parametrize("variant", VARIANTS)
def test_seeded_rollout_varies_reproducibly_within_the_action_range(tmp_path, variant):
    _, path = exported_agent(tmp_path, "debug", variant)
    runtime = load_agent(path)
    objectives = objectives_for_tests()[0]
    deterministic = runtime.rollout(objectives)
    varied = runtime.rollout(objectives, seed=5)
    np.testing.assert_array_equal(runtime.rollout(objectives, seed=5), varied)
    assert np.all((varied >= 0.0) & (varied <= 1.0))
    assert np.abs(varied - deterministic).max() > 1e-3
    assert np.abs(runtime.rollout(objectives, seed=6) - varied).max() > 1e-3

    def roughness(actions):  # mean second difference over frames and channels
        return np.abs(np.diff(actions, 2, axis=0)).mean()

    # noise drawn afresh each frame made these 350-800 times rougher than the deterministic rollout
    assert roughness(varied) < 4.0 * roughness(deterministic), "a seed varies the gesture; it must not make it jitter"


def rhythm_agent(tmp_path):
    """A debug-sized agent whose file carries the RHYTHM model."""
    torch.manual_seed(0)
    path = tmp_path / "rhythm.npz"
    export_agent(RLAnimateAgent(load_preset("debug")[0]), path,
                 {"average_frames": {"POINT": 80, "WAVE": 95}, "wave_rhythm": RHYTHM.to_dict()})
    return load_agent(path)


def test_the_wave_rhythm_comes_from_the_file_mean_without_a_seed_and_varied_with_one(tmp_path):
    agent = rhythm_agent(tmp_path)
    assert np.array_equal(agent.wave_rhythm(0.4, 90), rhythm.signals(RHYTHM.draw(0.4), 90))
    assert np.array_equal(agent.wave_rhythm(0.4, 90, seed=3), agent.wave_rhythm(0.4, 90, seed=3))
    assert np.abs(agent.wave_rhythm(0.4, 90, seed=3) - agent.wave_rhythm(0.4, 90, seed=4)).max() > 0.5
    _, plain = exported_agent(tmp_path, "debug", "rlanimate")
    assert load_agent(plain).wave_rhythm(0.4, 90) is None  # the paper's objective


def test_a_file_with_by_arm_plays_each_arm_from_its_own_arms_waves(tmp_path):
    by_arm = rhythm.RhythmModel.fit(
        RHYTHM.examples[:, 0],
        [
            rhythm.Rhythm(*row[1:], phase, RHYTHM.ramp)
            for row, phase in zip(RHYTHM.examples, RHYTHM.phases, strict=True)
        ],
        ["LEFT", "RIGHT", "LEFT"],
    ).with_settings(by_arm=True)
    torch.manual_seed(0)
    path = tmp_path / "by_arm.npz"
    export_agent(RLAnimateAgent(load_preset("debug")[0]), path, {"wave_rhythm": by_arm.to_dict()})
    agent = load_agent(path)
    assert agent.rhythm_model.arms == ("LEFT", "RIGHT", "LEFT") and agent.rhythm_model.by_arm
    for arm in ("LEFT", "RIGHT"):
        assert np.array_equal(agent.wave_rhythm(0.4, 90, arm=arm), rhythm.signals(by_arm.draw(0.4, arm=arm), 90))
    assert not np.allclose(agent.wave_rhythm(0.4, 90, arm="LEFT"), agent.wave_rhythm(0.4, 90, arm="RIGHT"))


def test_a_wave_swings_at_the_requested_tempo_within_what_the_agent_learned(tmp_path):
    agent = rhythm_agent(tmp_path)
    low, high = agent.tempo_range()  # Hz: the training waves' 0.072-0.08 cycles a frame at 30 fps, widened
    assert (low, high) == pytest.approx((0.072 * 30 / rhythm.TEMPO_MARGIN, 0.08 * 30 * rhythm.TEMPO_MARGIN))
    for tempo in (low, 2.0, high):
        signals = agent.wave_rhythm(0.4, 300, tempo=tempo)
        mean = RHYTHM.draw(0.4)
        swinging = np.arange(int(mean.start * 299) + 12, int(mean.stop * 299) - 12)  # inside the envelope's ramps
        turns = np.diff(np.unwrap(np.arctan2(signals[swinging, 0], signals[swinging, 1])))
        assert np.allclose(turns * 30 / (2 * np.pi), tempo), "a full swing's phase turns at the tempo"
    assert np.array_equal(agent.wave_rhythm(0.4, 90, seed=3, tempo=2.0), agent.wave_rhythm(0.4, 90, seed=3, tempo=2.0))
    for outside in (low * 0.9, high * 1.1, float("nan")):
        with pytest.raises(RLAnimateError, match=r"Tempo between \d+\.\d\d and \d+\.\d\d Hz, or to 0"):
            agent.wave_rhythm(0.4, 90, tempo=outside)
    _, plain = exported_agent(tmp_path, "debug", "rlanimate")
    with pytest.raises(RLAnimateError, match="trained without the waves' rhythm"):
        load_agent(plain).wave_rhythm(0.4, 90, tempo=2.0)
    assert load_agent(plain).tempo_range() is None


def test_metadata_accessors(tmp_path):
    _, path = exported_agent(tmp_path, "debug", "rlanimate")
    runtime = load_agent(path)
    assert runtime.average_frames == {"POINT": 80.0, "WAVE": 95.0}
    assert runtime.behaviours == ("POINT", "WAVE")
    assert runtime.action_bounds.shape == (spaces.ACTION_SIZE, 2)
    np.testing.assert_allclose(runtime.action_bounds, spaces.DEFAULT_ACTION_BOUNDS)
    assert runtime.metadata["variant"] == "rlanimate"


def test_shipped_default_agent_plays(tmp_path):
    from pathlib import Path
    runtime = load_agent(Path(__file__).resolve().parents[2] / "rlanimate_addon" / "agents" / "default.npz")
    assert runtime.behaviours[:2] == ("POINT", "WAVE"), "point and wave, as Table 2 has them, then any others"
    for name in runtime.behaviours:
        attributes = [0.0, -1.0, 0.0] if runtime.space.kind(name) == "target" else 0.5
        actions = runtime.rollout(runtime.space.make_objective(name, "LEFT", attributes, 40))
        assert actions.shape == (40, spaces.ACTION_SIZE)
        assert np.all(np.isfinite(actions)) and np.all((actions >= 0.0) & (actions <= 1.0))
    assert isinstance(runtime, GestureAgent)


@pytest.mark.parametrize("objectives", [np.zeros((0, 7)), np.zeros((5, 6)), np.zeros(7),
                                        np.full((4, 7), np.nan)])
def test_bad_objectives_get_a_clear_error(tmp_path, objectives):
    from rlanimate_addon.core.errors import RLAnimateError
    _, path = exported_agent(tmp_path, "debug", "rlanimate")
    with pytest.raises(RLAnimateError, match="objectives of shape"):
        load_agent(path).rollout(objectives)


def test_single_behaviour_agent_plays_only_its_behaviour(tmp_path):
    from rlanimate_addon.core.errors import RLAnimateError
    torch.manual_seed(0)
    path = tmp_path / "point.npz"
    export_agent(RLAnimateAgent(load_preset("debug")[0]), path, {"average_frames": {"POINT": 116.0}})
    runtime = load_agent(path)
    assert runtime.behaviours == ("POINT",)
    assert runtime.average_frames == {"POINT": 116.0, "WAVE": 116.0}
    point, wave, _ = objectives_for_tests()
    assert runtime.rollout(point).shape == (len(point), spaces.ACTION_SIZE)
    with pytest.raises(RLAnimateError, match="trained for point only"):
        runtime.rollout(wave)


def test_an_agent_of_four_declared_behaviours_lists_them_and_plays_each_with_its_label(tmp_path):
    from rlanimate_addon.core import behaviours
    from rlanimate_addon.core.behaviours import INTENSITY, TARGET, Behaviour
    from rlanimate_addon.core.errors import RLAnimateError
    space = spaces.ObjectiveSpace(behaviours.ordered([*behaviours.PAPER, Behaviour("THIS_WAY", TARGET),
                                                      Behaviour("RAISE_HAND", INTENSITY)]))
    torch.manual_seed(0)
    agent = RLAnimateAgent(load_preset("debug")[0], "rlanimate", space)
    path = tmp_path / "four.npz"
    export_agent(agent, path, {"average_frames": {"POINT": 80, "WAVE": 95, "THIS_WAY": 70}})
    runtime = load_agent(path)
    assert runtime.space == space and runtime.behaviours == ("POINT", "WAVE", "THIS_WAY")
    assert runtime.kind("THIS_WAY") == TARGET and runtime.kind("RAISE_HAND") == INTENSITY
    assert runtime.average_frames["RAISE_HAND"] == pytest.approx((80 + 95 + 70) / 3)
    guide = space.make_objective("THIS_WAY", "LEFT", [0.3, -0.9, 0.2], 40)
    actions = runtime.rollout(guide)
    np.testing.assert_allclose(actions, torch_rollout(agent, guide), atol=1e-5)
    other = runtime.rollout(space.make_objective("POINT", "LEFT", [0.3, -0.9, 0.2], 40))
    assert np.abs(actions - other).max() > 1e-4, "the label changes the gesture"
    with pytest.raises(RLAnimateError, match="trained for point and wave and this_way only"):
        runtime.rollout(space.make_objective("RAISE_HAND", "LEFT", 0.5, 40))
    with pytest.raises(RLAnimateError, match=r"objectives of shape \(frames, 10\)"):
        runtime.rollout(spaces.PAPER_SPACE.make_objective("POINT", "LEFT", [0.3, -0.9, 0.2], 40))
