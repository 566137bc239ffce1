"""The behaviour model's written-out unroll against the same unroll recorded by autograd."""
import pytest
import torch
from torch import nn

from trainer.agent import unroll
from trainer.agent.config import AgentConfig
from trainer.agent.losses import concentration_nll
from trainer.agent.models import RLAnimateAgent


def recorded_unroll(cell, posterior, task, previous_actions, conditions, noise, min_std):
    """The unroll as RLAnimateAgent.observe first wrote it: GRUCell, the posterior MLP, z = mean + noise * std,
    each frame recorded by autograd."""
    e = task.new_zeros(task.shape[0], cell.hidden_size)
    z = task.new_zeros(task.shape[0], noise.shape[-1])
    outputs = {"e": [], "z": [], "mean": [], "std": []}
    for t in range(task.shape[1]):
        e = cell(torch.cat([task[:, t], z, previous_actions[:, t]], -1), e)
        mean, raw = posterior(torch.cat([e, conditions[:, t]], -1)).chunk(2, -1)
        std = nn.functional.softplus(raw) + min_std
        z = mean + noise[t] * std
        for name, value in (("e", e), ("z", z), ("mean", mean), ("std", std)):
            outputs[name].append(value)
    return tuple(torch.stack(outputs[name], 1) for name in ("e", "z", "mean", "std"))


@pytest.mark.parametrize("layers", [1, 2, 3])
@pytest.mark.parametrize("variant", ["rlanimate", "single_state"])
def test_observe_matches_the_recorded_unroll_with_its_gradients(layers, variant):
    torch.manual_seed(0)
    agent = RLAnimateAgent(AgentConfig(task_size=12, behaviour_size=10, stochastic_size=4, hidden_size=9,
                                       portrayal_hidden_size=8, hidden_layers=layers), variant).double()
    objectives, actions, conditions = (torch.rand(5, 7, size, dtype=torch.float64) for size in (7, 45, 42))
    weights = torch.Generator().manual_seed(1)

    def loss_and_grads(unrolled_by):
        agent.zero_grad()
        torch.manual_seed(5)  # the same noise for both
        if unrolled_by == "autograd":
            task = agent.task_features(objectives)
            noise = torch.empty(7, 5, 4, dtype=torch.float64).normal_()
            e, z, mean, std = recorded_unroll(agent.behaviour_cell, agent.posterior, task, actions, conditions, noise,
                                              agent.config.min_std)
            features = agent.features(task, e, z)
        else:
            observed = agent.observe(objectives, actions, conditions)
            features, mean, std = observed["features"], observed["posterior"].mean, observed["posterior"].stddev
            e = features[..., -14:-4] if agent.uses_task_state else features[..., :10]
        mixed = torch.randn(features.shape, generator=weights.manual_seed(1), dtype=torch.float64)
        loss = (features * mixed).sum() + (mean ** 3).sum() + std.log().sum() + agent.prior(e).pow(2).sum()
        loss.backward()
        return features.detach(), {name: p.grad.clone() for name, p in agent.named_parameters() if p.grad is not None}

    recorded, written = loss_and_grads("autograd"), loss_and_grads("unroll")
    assert torch.allclose(recorded[0], written[0], atol=1e-12)
    assert recorded[1].keys() == written[1].keys()
    assert all(torch.allclose(recorded[1][name], written[1][name], atol=1e-10) for name in recorded[1])


def test_the_unroll_passes_gradcheck():
    torch.manual_seed(2)
    size, stochastic, hidden, chunks, frames = 3, 2, 4, 2, 3
    inputs = [torch.randn(chunks, frames, 3 * size), torch.randn(chunks, frames, hidden),
              torch.randn(frames, chunks, stochastic), torch.randn(3 * size, stochastic), torch.randn(3 * size, size),
              torch.randn(3 * size), torch.randn(hidden, size)]
    later = [(torch.randn(hidden, hidden), torch.randn(hidden)), (torch.randn(2 * stochastic, hidden),
                                                                   torch.randn(2 * stochastic))]
    inputs = [t.double().requires_grad_(k != 2) for k, t in enumerate(inputs)]
    later = [tuple(t.double().requires_grad_() for t in layer) for layer in later]

    def outputs(*tensors):
        return unroll.posterior_unroll(*tensors[:7], list(zip(tensors[7::2], tensors[8::2], strict=True)), 0.1)

    assert torch.autograd.gradcheck(outputs, (*inputs, *[t for layer in later for t in layer]))


def test_the_policy_nll_is_the_betas_with_its_mean_held():
    alpha, beta = (1.0 + 20.0 * torch.rand(3, 4, 45, dtype=torch.float64) for _ in range(2))
    motion = torch.rand(3, 4, 45, dtype=torch.float64)
    concentration = (alpha + beta).requires_grad_()
    mean = alpha / (alpha + beta)
    nll = concentration_nll(mean * concentration, (1 - mean) * concentration, motion)
    expected = -torch.distributions.Beta(mean * concentration, (1 - mean) * concentration).log_prob(
        motion.clamp(1e-3, 1 - 1e-3)).sum(-1)
    assert torch.allclose(nll, expected, atol=1e-9)
    nll.sum().backward()
    assert torch.isfinite(concentration.grad).all() and concentration.grad.abs().sum() > 0
