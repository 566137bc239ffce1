"""The training objective (paper Section 3.3, equation 4: L1 + L2 + L3), plus two small extra terms.

On a batch of C chunks of L frames (batch-major, from trainer/agent/buffer.py):
    description  the paper's L1: MSE of the decoder's p(d_t | h_t, b_t) against the real description
                 d'_t, summed over the 42 numbers, averaged over frames;
    kl           the paper's L2: KL(q || p) with KL balancing (DreamerV2: `kl_balance` of the gradient
                 trains the prior, the rest the posterior) and free nats (each side's mean KL per frame
                 is clamped from below at `free_nats`, so a KL already that small is not pushed further);
    pose         the paper's L3: Huber(M_t, mean of the animation model's Beta), summed over the 45
                 channels. It flows back through the behaviour model into the portrayal model, because
                 the posterior is conditioned on the portrayal's self-description, as at inference;
    portrayal    optional direct MSE of the self-description toward the clip's description (summed
                 over the 42 numbers), when `portrayal_direct_loss`;
    policy       negative log-likelihood of the clip's pose under the Beta with its mean held fixed, so
                 only the concentrations learn: the spread of stochastic rollouts tracks the agent's
                 remaining error instead of staying at its initial value;
    total        the sum of each term times its `*_scale`.
The previous action a_{t-1} is the buffer's (the agent's own earlier rollout, teacher forced); the
supervised variant is behaviour cloning instead: a_{t-1} is the clip's pose M_{t-1}, the description
term's target is the clip's description, and there is no KL term. docs/AGENT.md gives the reasons.
"""
import torch
import torch.nn.functional as F
from torch.distributions import Beta, Independent, kl_divergence

from rlanimate_addon.core.agent_file import INITIAL_ACTION

#: Clip poses are kept this far inside (0, 1) for the Beta's log-likelihood.
POSE_MARGIN = 1e-3


def agent_losses(agent, batch, config):
    """{"description", "kl", "pose", "portrayal", "policy", "total"}: scalar tensors for `agent` on `batch`."""
    objective, motion = batch["objective"], batch["motion"]  # (C, L, 7), (C, L, 45)
    supervised = agent.variant == "supervised"
    played = motion if supervised else batch["action"]  # (C, L, 45)
    previous = torch.cat([torch.full_like(played[:, :1], INITIAL_ACTION), played[:, :-1]], 1)  # a_{t-1}
    described = agent.self_description(objective)  # (C, L, 42) or None
    conditions = batch["description"] if described is None else described
    unrolled = agent.observe(objective, previous, conditions)
    features = unrolled["features"]  # (C, L, F)

    description_target = batch["motion_description"] if supervised else batch["description"]
    terms = {"description": squared_error(agent.decode(features), description_target)}  # the paper's L1
    terms["kl"] = (torch.zeros((), dtype=objective.dtype) if supervised else  # L2
                   balanced_kl(unrolled["posterior"], unrolled["prior"], config.kl_balance, config.free_nats))
    policy = agent.policy(features)
    pose_error = F.huber_loss(policy.mean, motion, reduction="none", delta=config.huber_delta)  # (C, L, 45)
    terms["pose"] = pose_error.sum(-1).mean()  # L3
    terms["portrayal"] = (squared_error(described, batch["motion_description"])
                          if described is not None and config.portrayal_direct_loss
                          else torch.zeros((), dtype=objective.dtype))
    terms["policy"] = concentration_nll(policy, motion)
    scales = {"description": config.description_scale, "kl": config.kl_scale, "pose": config.pose_scale,
              "portrayal": config.portrayal_scale, "policy": config.policy_scale}
    terms["total"] = sum(scales[name] * value for name, value in terms.items())
    return terms


def squared_error(prediction, target):
    """Squared error summed over the last axis, averaged over the others."""
    return (prediction - target).pow(2).sum(-1).mean()


def balanced_kl(posterior, prior, balance, free_nats):
    """KL(q || p) per frame, balanced between training the prior and the posterior, with free nats."""
    def detached(dist):
        return Independent(type(dist.base_dist)(dist.base_dist.loc.detach(), dist.base_dist.scale.detach()), 1)

    train_prior = kl_divergence(detached(posterior), prior).mean().clamp(min=free_nats)
    train_posterior = kl_divergence(posterior, detached(prior)).mean().clamp(min=free_nats)
    return balance * train_prior + (1.0 - balance) * train_posterior


def concentration_nll(policy, motion):
    """-log Beta(M_t) with the Beta's mean detached: trains only its concentration alpha + beta."""
    alpha, beta = policy.base_dist.concentration1, policy.base_dist.concentration0
    concentration = alpha + beta
    mean = (alpha / concentration).detach()
    fixed_mean = Beta(mean * concentration, (1.0 - mean) * concentration)
    return -fixed_mean.log_prob(motion.clamp(POSE_MARGIN, 1.0 - POSE_MARGIN)).sum(-1).mean()
