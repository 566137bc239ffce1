"""The training objective (paper Section 3.3, equation 4: L1 + L2 + L3), plus two small extra terms.

On a batch of C chunks of L frames (batch-major, from trainer/agent/buffer.py):
    description  the paper's L1: MSE of the decoder's p(d_t | h_t, b_t) against the real description
                 d'_t, summed over the 42 numbers, averaged over frames;
    kl           the paper's L2: KL(q || p) with KL balancing (DreamerV2: `kl_balance` of the gradient
                 trains the prior, the rest the posterior) and free nats (each side's mean KL per frame
                 is clamped from below at `free_nats`, so a KL already that small is not pushed further);
    pose         the paper's L3: Huber(M_t, mean of the animation model's Beta), summed over the 45
                 channels, over the frames that imitate a clip (not the random-target pointing
                 requests). It flows back through the behaviour model into the portrayal model, because
                 the posterior is conditioned on the portrayal's self-description, as at inference;
    portrayal    optional direct MSE of the self-description toward the clip's description (summed
                 over the 42 numbers), when `portrayal_direct_loss`;
    velocity     optional (`velocity_scale` > 0): Huber of the Beta mean's change from frame to frame to
                 the clip's, summed over the 45 channels, where both frames imitate a clip;
    wrist        optional (`wrist_scale` > 0): squared distance (m^2) between the gesturing wrist of the
                 Beta mean's pose and the clip's, through differentiable forward kinematics, on the
                 frames of intensity behaviours (wave) that imitate a clip: the hand path the swing is
                 measured on;
    pointing     the agent's own finger line against the objective's ray at the frames where the clip
                 holds its point (trainer/agent/pointing.py), through differentiable forward kinematics
                 of the Beta's mean pose; on when the action bounds are given;
    policy       negative log-likelihood of the clip's pose under the Beta with its mean held fixed, so
                 only the concentrations learn: the spread of stochastic rollouts tracks the agent's
                 remaining error instead of staying at its initial value;
    total        the sum of each term times its `*_scale` (1.0 for a term without one).
The previous action a_{t-1} is the buffer's (the agent's own earlier rollout, teacher forced); the
supervised variant is behaviour cloning instead: a_{t-1} is the clip's pose M_{t-1}, the description
term's target is the clip's description, and there is no KL term. docs/AGENT.md gives the reasons.
"""
import torch
import torch.nn.functional as F
from torch.distributions import Independent, kl_divergence

from rlanimate_addon.core import behaviours
from rlanimate_addon.core.agent_file import INITIAL_ACTION
from trainer.agent import pointing
from trainer.agent.arm_kinematics import ARMS, action_rotvecs, arm_indices

#: Clip poses are kept this far inside (0, 1) for the Beta's log-likelihood.
POSE_MARGIN = 1e-3


def agent_losses(agent, batch, config, bounds=None):
    """{"description", "kl", "pose", "portrayal", "pointing", "policy", "total"}, and "velocity" when its
    scale is not 0: scalar tensors for `agent` on `batch`; the pointing term is zero without the action
    `bounds` (45, 2) or the batch's "hold"."""
    objective, motion = batch["objective"], batch["motion"]  # (C, L, O), (C, L, 45)
    supervised = agent.variant == "supervised"
    played = motion if supervised else batch["action"]  # (C, L, 45)
    previous = torch.cat([torch.full_like(played[:, :1], INITIAL_ACTION), played[:, :-1]], 1)  # a_{t-1}
    described = agent.self_description(objective)  # (C, L, 42) or None
    # The posterior's input: the self-description, or in single_state the real description d'_t, or
    # with posterior_on_reference the clip's own description (the prior is what the rollout plays).
    conditions = described if described is not None else \
        batch["motion_description"] if config.posterior_on_reference else batch["description"]
    unrolled = agent.observe(objective, previous, conditions)
    features = unrolled["features"]  # (C, L, F)

    description_target = batch["motion_description"] if supervised else batch["description"]
    terms = {"description": squared_error(agent.decode(features), description_target)}  # the paper's L1
    terms["kl"] = (torch.zeros((), dtype=objective.dtype) if supervised else  # L2
                   balanced_kl(unrolled["posterior"], unrolled["prior"], config.kl_balance, config.free_nats))
    imitate = batch.get("imitate", torch.ones_like(objective[..., 0]))  # (C, L): 0 on random-target requests
    alpha, beta = agent.policy_concentrations(features)  # the animation model's Beta, (C, L, 45) each
    pose = alpha / (alpha + beta)  # its mean, the pose the agent plays
    pose_error = F.huber_loss(pose, motion, reduction="none", delta=config.huber_delta)  # (C, L, 45)
    terms["pose"] = masked_mean(pose_error.sum(-1), imitate)  # L3
    if config.velocity_scale:  # only then: runs without it log the terms they always had
        terms["velocity"] = velocity_error(pose, motion, imitate, config.huber_delta)
    terms["portrayal"] = (masked_mean((described - batch["motion_description"]).pow(2).sum(-1), imitate)
                          if described is not None and config.portrayal_direct_loss
                          else torch.zeros((), dtype=objective.dtype))
    terms["pointing"] = torch.zeros((), dtype=objective.dtype)
    hold = batch["hold"] > 0.5 if "hold" in batch else None  # (C, L)
    if bounds is not None and hold is not None and hold.any():
        terms["pointing"] = pointing.pointing_error(pose[hold], objective[hold],
                                                    torch.as_tensor(bounds, dtype=objective.dtype)).mean()
    if config.wrist_scale and bounds is not None:  # only then: runs without it log the terms they always had
        waving = of_kind(agent.space, objective, behaviours.INTENSITY) & (imitate > 0.5)  # (C, L)
        terms["wrist"] = (wrist_error(pose[waving], motion[waving], objective[waving],
                                      torch.as_tensor(bounds, dtype=objective.dtype)).mean()
                          if waving.any() else torch.zeros((), dtype=objective.dtype))
    terms["policy"] = masked_mean(concentration_nll(alpha, beta, motion), imitate)
    scales = {"description": config.description_scale, "kl": config.kl_scale, "pose": config.pose_scale,
              "velocity": config.velocity_scale, "wrist": config.wrist_scale,
              "portrayal": config.portrayal_scale, "pointing": config.pointing_scale, "policy": config.policy_scale}
    terms["total"] = weighted_total(terms, scales)
    return terms


def weighted_total(terms, scales):
    """The sum of each of `terms` ({name: scalar tensor}) times its scale in `scales`; a term that has none counts
    once (scale 1.0)."""
    return sum(scales.get(name, 1.0) * value for name, value in terms.items())


def of_kind(space, objective, kind):
    """(C, L) bool: the frames of objective (C, L, O) whose label is one of `kind`'s behaviours in `space`."""
    labels = torch.as_tensor(space.labels[[space.names.index(n) for n in space.of_kind(kind)]],
                             dtype=objective.dtype)  # (K, L_label)
    return (objective[..., None, :space.label_size] == labels).all(-1).any(-1)


def velocity_error(poses, motion, imitate, delta):
    """Huber of the poses' (C, L, 45) change from frame to frame against the clip's, summed over the
    channels, averaged over the frame pairs that both imitate the clip (imitate (C, L))."""
    error = F.huber_loss(poses.diff(dim=1), motion.diff(dim=1), reduction="none", delta=delta)  # (C, L - 1, 45)
    return masked_mean(error.sum(-1), imitate[:, 1:] * imitate[:, :-1])


def wrist_error(actions, motion, objectives, bounds):
    """(N,) squared distance (m^2) between the wrist of actions (N, 45) and of the clip's poses motion
    (N, 45), each frame on its objective's (N, 7) arm: the hand path a wave's swing is measured on."""
    arms = arm_indices(objectives)
    with torch.no_grad():  # the clip's wrist is a target
        target = ARMS.wrist(action_rotvecs(motion, bounds), arms)
    return (ARMS.wrist(action_rotvecs(actions, bounds), arms) - target).pow(2).sum(-1)


def masked_mean(values, mask):
    """Mean of values (C, L) over the frames where mask (C, L) is 1 (0 when there are none)."""
    return (values * mask).sum() / mask.sum().clamp(min=1.0)


def squared_error(prediction, target):
    """Squared error summed over the last axis, averaged over the others."""
    return (prediction - target).pow(2).sum(-1).mean()


def balanced_kl(posterior, prior, balance, free_nats):
    """KL(q || p) per frame, balanced between training the prior and the posterior, with free nats."""
    def detached(dist):
        base = type(dist.base_dist)(dist.base_dist.loc.detach(), dist.base_dist.scale.detach(), validate_args=False)
        return Independent(base, 1, validate_args=False)

    train_prior = kl_divergence(detached(posterior), prior).mean().clamp(min=free_nats)
    train_posterior = kl_divergence(posterior, detached(prior)).mean().clamp(min=free_nats)
    return balance * train_prior + (1.0 - balance) * train_posterior


def concentration_nll(alpha: torch.Tensor, beta: torch.Tensor, motion: torch.Tensor) -> torch.Tensor:
    """(C, L) -log Beta(M_t) under the Beta (alpha, beta) (C, L, 45) with its mean held fixed: trains only its
    concentration alpha + beta. The Beta density written out: torch.distributions' Beta stacks its parameters
    and the pose into a Dirichlet's, which made this term 1.6x dearer (6 ms of an update step)."""
    concentration = alpha + beta
    mean = (alpha / concentration).detach()
    alpha, beta = mean * concentration, (1.0 - mean) * concentration
    pose = motion.clamp(POSE_MARGIN, 1.0 - POSE_MARGIN)
    log_density = ((alpha - 1.0) * torch.log(pose) + (beta - 1.0) * torch.log(1.0 - pose)
                   + torch.lgamma(concentration) - torch.lgamma(alpha) - torch.lgamma(beta))
    return -log_density.sum(-1)
