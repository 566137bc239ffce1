"""The torch agent: shapes, the file layout it exports, losses that fall, and gradients that reach
the portrayal model through the pose term (the paper's L3)."""
import dataclasses

import numpy as np
import pytest
import torch

from rlanimate_addon.core import agent_file, spaces
from trainer.agent.config import PRESETS, AgentConfig, TrainConfig, load_preset
from trainer.agent.models import VARIANTS, RLAnimateAgent

torch.set_num_threads(1)


def synthetic_batch(chunks, length, seed=0):
    """Chunks whose clip pose and description are smooth functions of the objective (learnable)."""
    generator = torch.Generator().manual_seed(seed)
    objective = torch.zeros(chunks, length, spaces.PAPER_SPACE.size)
    objective[..., 0] = torch.randint(1, 3, (chunks, 1), generator=generator).float()
    objective[..., 1] = torch.randint(0, 2, (chunks, 1), generator=generator).float()
    objective[..., 2] = 1.0 - objective[..., 1]
    objective[..., 3:6] = torch.rand(chunks, 1, 3, generator=generator)
    start = torch.rand(chunks, 1, generator=generator) * 0.5
    objective[..., 6] = start + torch.linspace(0.0, 0.5, length)
    phase = objective[..., 6:7] * torch.arange(1, spaces.ACTION_SIZE + 1) / 10.0  # (C, L, 45)
    motion = 0.5 + 0.3 * torch.sin(3.0 * phase + objective[..., 3:4])
    description = torch.cat([motion[..., :21], motion[..., :21] ** 2], -1)  # (C, L, 42)
    action = (motion + 0.05 * torch.randn(motion.shape, generator=generator)).clamp(0.0, 1.0)
    return {"objective": objective, "action": action, "description": description + 0.01,
            "motion": motion, "motion_description": description}


@pytest.mark.parametrize("variant", VARIANTS)
def test_parameters_match_the_agent_file_layout(variant):
    config, _ = load_preset("debug")
    agent = RLAnimateAgent(config, variant)
    shapes = {name: tuple(t.shape) for name, t in agent.state_dict().items()}
    expected = {
        name: tuple(s)
        for name, s in agent_file.expected_weight_shapes(config.to_dict(), variant, agent.space.size).items()
    }
    assert shapes == expected


@pytest.mark.parametrize("variant", VARIANTS)
def test_rollout_shapes_and_range(variant):
    config, _ = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(config, variant)
    objectives = synthetic_batch(3, 11)["objective"]
    deterministic = agent.rollout(objectives)
    sampled = agent.rollout(objectives, deterministic=False, generator=torch.Generator().manual_seed(4))
    for actions in (deterministic, sampled):
        assert actions.shape == (3, 11, spaces.ACTION_SIZE)
        assert torch.all((actions >= 0.0) & (actions <= 1.0))
        assert not actions.requires_grad
    assert torch.equal(deterministic, agent.rollout(objectives))
    assert not torch.allclose(deterministic, sampled)


def test_sampled_rollout_is_reproducible_from_its_generator_alone():
    config, _ = load_preset("debug")
    agent = RLAnimateAgent(config)
    objectives = synthetic_batch(2, 9)["objective"]
    first = agent.rollout(objectives, deterministic=False, generator=torch.Generator().manual_seed(7))
    torch.manual_seed(123)  # the global RNG must not matter
    second = agent.rollout(objectives, deterministic=False, generator=torch.Generator().manual_seed(7))
    assert torch.equal(first, second)


def test_losses_report_every_term_as_a_finite_scalar():
    config, train = load_preset("debug")
    losses = RLAnimateAgent(config).losses(synthetic_batch(4, 8), train)
    assert set(losses) == {"description", "kl", "pose", "portrayal", "pointing", "policy", "total"}
    for value in losses.values():
        assert value.shape == () and torch.isfinite(value)
    scales = {"description": train.description_scale, "kl": train.kl_scale, "pose": train.pose_scale,
              "portrayal": train.portrayal_scale, "policy": train.policy_scale}
    expected_total = sum(scales[name] * losses[name] for name in scales)
    assert torch.allclose(losses["total"], expected_total)


@pytest.mark.parametrize("variant", VARIANTS)
def test_losses_fall_on_a_tiny_batch(variant):
    config, train = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(config, variant)
    batch = synthetic_batch(6, 10)
    optimiser = torch.optim.Adam(agent.parameters(), lr=2e-2)
    history = []
    for _ in range(50):
        losses = agent.losses(batch, train)
        optimiser.zero_grad()
        losses["total"].backward()
        optimiser.step()
        history.append({name: float(value.detach()) for name, value in losses.items()})
    assert history[-1]["total"] < 0.5 * history[0]["total"]
    assert history[-1]["pose"] < 0.75 * history[0]["pose"]
    assert history[-1]["description"] < 0.5 * history[0]["description"]


def test_l3_reaches_the_portrayal_model_through_the_behaviour_model():
    config, train = load_preset("debug")
    agent = RLAnimateAgent(config)
    agent.losses(synthetic_batch(4, 8), dataclasses.replace(train, portrayal_direct_loss=False))["pose"].backward()
    for name, parameter in agent.named_parameters():
        if name.startswith(("portrayal.", "task_rnn.", "behaviour_cell.", "posterior.", "animation.")):
            assert parameter.grad is not None and parameter.grad.abs().sum() > 0, name


def test_portrayal_direct_loss_can_be_switched_off():
    config, train = load_preset("debug")
    agent = RLAnimateAgent(config)
    batch = synthetic_batch(4, 8)
    assert float(agent.losses(batch, train)["portrayal"].detach()) > 0.0
    switched_off = dataclasses.replace(train, portrayal_direct_loss=False)
    assert float(agent.losses(batch, switched_off)["portrayal"].detach()) == 0.0


def test_supervised_variant_clones_the_clip_without_kl():
    config, train = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(config, "supervised")
    batch = synthetic_batch(4, 8)
    losses = agent.losses(batch, train)
    assert float(losses["kl"]) == 0.0
    torch.manual_seed(1)
    changed = dict(batch, action=torch.rand_like(batch["action"]),
                   description=torch.rand_like(batch["description"]))
    torch.manual_seed(1)
    same = agent.losses(batch, train)
    torch.manual_seed(1)
    assert torch.equal(agent.losses(changed, train)["total"], same["total"])  # ignores the rollout data


def test_presets_and_config_round_trip():
    assert set(PRESETS) == {"debug", "default", "paper", "paper_wave_objective", "reference_posterior",
                            "no_random_targets", "no_pointing_term", "velocity_term", "weight_average", "no_wrist_term",
                            "end_chunks", "end_chunks_wide", "end_chunks_long", "end_chunks_smooth",
                            "end_chunks_phase", "end_chunks_phase_smooth", "end_chunks_tempo_smooth"}
    for name in PRESETS:
        agent_config, train_config = load_preset(name)
        assert AgentConfig.from_dict(agent_config.to_dict()) == agent_config
        assert TrainConfig.from_dict(train_config.to_dict()) == train_config
    debug, default = load_preset("debug")[0], load_preset("default")[0]
    assert sum(p.numel() for p in RLAnimateAgent(debug).parameters()) < \
        sum(p.numel() for p in RLAnimateAgent(default).parameters()) / 10


def test_train_configs_defaults_are_the_default_preset_and_debug_and_paper_keep_the_first_ones():
    assert load_preset("default")[1] == TrainConfig()
    first = {"update_steps_many": None, "chunk_count_many": None, "learning_rate": 1e-3, "learning_rate_final": None,
             "wrist_scale": 0.0, "random_targets": 1, "random_target_margin_deg": 0.0, "random_target_weight": 1.0}
    for name in ("debug", "paper"):
        assert {key: getattr(load_preset(name)[1], key) for key in first} == first


def test_unknown_preset_names_the_choices():
    from rlanimate_addon.core.errors import RLAnimateError
    with pytest.raises(RLAnimateError, match="debug"):
        load_preset("huge")


def test_default_agent_fits_in_two_megabytes_of_float32():
    agent = RLAnimateAgent(load_preset("default")[0])
    assert 4 * sum(p.numel() for p in agent.parameters()) < 2e6
    assert all(torch.isfinite(p.detach()).all() for p in agent.parameters())


def test_the_reference_posterior_sees_the_clips_description_and_not_the_rollouts():
    config, train = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(config, "single_state")
    batch = synthetic_batch(4, 8)
    moved = dict(batch, motion_description=batch["motion_description"] + 0.5)
    train = dataclasses.replace(train, free_nats=0.0)  # free nats would clamp both KLs to the same floor
    reference = dataclasses.replace(train, posterior_on_reference=True)

    def kl(settings, chunks):
        torch.manual_seed(3)
        return float(agent.losses(chunks, settings)["kl"].detach())

    assert kl(reference, moved) != kl(reference, batch)
    assert kl(train, moved) == kl(train, batch)  # single_state's own posterior: the rollout's d'_t


def test_the_ablation_presets_change_one_choice_each():
    default = PRESETS["default"][1]
    changed = {name: {f.name for f in dataclasses.fields(TrainConfig)
                      if getattr(PRESETS[name][1], f.name) != getattr(default, f.name)}
               for name in ("paper_wave_objective", "reference_posterior", "no_random_targets", "no_pointing_term",
                            "velocity_term", "weight_average", "no_wrist_term")}
    assert changed == {"paper_wave_objective": {"wave_rhythm"},
                       "reference_posterior": {"wave_rhythm", "posterior_on_reference"},
                       "no_random_targets": {"random_targets"},
                       "no_pointing_term": {"random_targets", "pointing_scale"},
                       "velocity_term": {"velocity_scale"},
                       "weight_average": {"average_last_epochs"},
                       "no_wrist_term": {"wrist_scale"}}


def test_the_velocity_term_sees_a_still_arm_on_a_wave_and_not_an_offset_pose():
    from trainer.agent.losses import velocity_error
    t = torch.arange(40, dtype=torch.float32)
    wave = (0.5 + 0.1 * torch.sin(2 * torch.pi * t / 12))[None, :, None].expand(2, 40, 45)  # (C, L, 45)
    imitate = torch.ones(2, 40)
    still = torch.full_like(wave, 0.5)
    assert float(velocity_error(wave + 0.05, wave, imitate, 0.05)) == pytest.approx(0.0, abs=1e-6)
    assert float(velocity_error(still, wave, imitate, 0.05)) > 0.01
    assert float(velocity_error(still, wave, torch.zeros(2, 40), 0.05)) == 0.0  # random-target requests


def test_the_velocity_term_is_logged_and_counted_only_when_on():
    config, train = load_preset("debug")
    agent = RLAnimateAgent(config)
    batch = synthetic_batch(4, 8)
    assert "velocity" not in agent.losses(batch, train)
    torch.manual_seed(0)
    off = agent.losses(batch, train)
    torch.manual_seed(0)
    on = agent.losses(batch, dataclasses.replace(train, velocity_scale=10.0))
    assert torch.isfinite(on["velocity"]) and float(on["velocity"].detach()) > 0.0
    assert torch.allclose(on["total"], off["total"] + 10.0 * on["velocity"])


def test_the_wrist_term_is_logged_and_counted_only_when_on_and_given_the_bounds():
    config, train = load_preset("debug")
    agent = RLAnimateAgent(config)
    batch = synthetic_batch(6, 8)
    bounds = np.asarray(spaces.DEFAULT_ACTION_BOUNDS)
    assert "wrist" not in agent.losses(batch, train, bounds)
    torch.manual_seed(0)
    off = agent.losses(batch, train, bounds)
    torch.manual_seed(0)
    on = agent.losses(batch, dataclasses.replace(train, wrist_scale=10.0), bounds)
    assert float(on["wrist"].detach()) > 0.0
    assert torch.allclose(on["total"], off["total"] + 10.0 * on["wrist"])
