"""The RLAnimate agent (paper Section 3.1): portrayal, behaviour and animation models, and a decoder.

Timing of one rollout step (the environment plays a_t and returns the real description d'_t):

                  frame t-1                  frame t
    objective     o_{t-1}                    o_t
    portrayal     d_{t-1}                    d_t = g(o_t)                               self-description
    task state    h_{t-1} -----------------> h_t = f1(h_{t-1}, o_t)
    behaviour     e_{t-1} -----------------> e_t = f2(e_{t-1}; h_t, z_{t-1}, a_{t-1})
                  z_{t-1} ------------------------------------^   |
                  a_{t-1} ------------------------------------^   v
                                             z_t ~ q(z_t | e_t, d_t)                    prior p(z_t | e_t)
    animation                                a_t ~ Beta(h_t, e_t, z_t)                  played at frame t
    environment   d'_{t-1} = FK(a_{t-1})     d'_t = FK(a_t)           decoder(h_t, e_t, z_t) predicts d'_t

Everything indexed t is computed at frame t from o_t and from the previous frame's z_{t-1} and
a_{t-1}; a_t is the pose played at frame t and d'_t is the description of that pose. The
behaviour state b_t of the paper is the pair (e_t, z_t), as in PlaNet's RSSM. A rollout or a
training chunk starts from h_0 = e_0 = 0, z_0 = 0 and a_0 = agent_file.INITIAL_ACTION.

Variants (the paper's Table 4 ablations; docs/AGENT.md defines them):
    rlanimate        as above;
    single_state     the objective as a single state: no portrayal model and no task state (f2 takes
                     o_t in place of h_t, the heads see (e_t, z_t)); the posterior is conditioned on
                     the real description d'_t in training, and rollouts use the prior p(z_t | e_t);
    single_dynamics  no task state: f2 takes o_t in place of h_t, and the heads see (e_t, z_t) only;
    supervised       rlanimate's networks trained as behaviour cloning (trainer/agent/losses.py).
Tensors are batch-major: B sequences of T frames.
"""
import torch
import torch.nn.functional as F
from torch import nn
from torch.distributions import Beta, Independent, Normal

from rlanimate_addon.core import agent_file, rhythm, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent import losses as loss_terms
from trainer.agent import unroll

VARIANTS = agent_file.VARIANTS


def gaussian(mean, std):
    """Diagonal Gaussian over the last axis. Its arguments are not validated: the per-frame checks
    cost about 5% of an update step, and softplus + min_std keeps the sd positive."""
    return Independent(Normal(mean, std, validate_args=False), 1, validate_args=False)


def swing_rate(sine, cosine):
    """(B, T) A sin, A cos -> (B, T, 1): the swing's phase advance per frame (core.rhythm.swing_rate, in torch)."""
    real = cosine[..., 1:] * cosine[..., :-1] + sine[..., 1:] * sine[..., :-1]  # (B, T - 1): z_{t+1} conj(z_t)
    imaginary = sine[..., 1:] * cosine[..., :-1] - cosine[..., 1:] * sine[..., :-1]
    swinging = real ** 2 + imaginary ** 2 > rhythm.STILL_PRODUCT
    advance = torch.where(swinging, torch.atan2(imaginary, real), torch.zeros_like(real))
    none = sine.new_zeros(sine.shape[:-1] + (1,))
    still = none.bool()
    ahead, ahead_swings = torch.cat([advance, none], -1), torch.cat([swinging, still], -1)
    behind, behind_swings = torch.cat([none, advance], -1), torch.cat([still, swinging], -1)
    return torch.where(ahead_swings, ahead, torch.where(behind_swings, behind, none))[..., None]


class MLP(nn.Module):
    """`layers` hidden Linear + tanh layers of width `hidden`, then a Linear output (tanh: smooth, and one
    cheap call in the numpy runtime)."""

    def __init__(self, inputs, hidden, layers, outputs):
        super().__init__()
        widths = [inputs] + [hidden] * layers + [outputs]
        self.layers = nn.ModuleList(nn.Linear(n_in, n_out) for n_in, n_out in zip(widths[:-1], widths[1:], strict=True))

    def forward(self, x):
        for layer in self.layers[:-1]:
            x = torch.tanh(layer(x))
        return self.layers[-1](x)


class RLAnimateAgent(nn.Module):
    """The agent for objectives of `space` (a core.spaces.ObjectiveSpace: its behaviours; point and wave
    by default), whose size O is the width of every objective tensor below."""

    def __init__(self, agent_config, variant="rlanimate", space=spaces.PAPER_SPACE):
        super().__init__()
        if variant not in VARIANTS:
            raise RLAnimateError(f"Unknown agent variant {variant!r}: use one of {', '.join(VARIANTS)}.")
        c = self.config = agent_config
        self.variant = variant
        self.space = space
        O, D, A = space.size, spaces.DESCRIPTION_SIZE, spaces.ACTION_SIZE  # noqa: E741 (the paper's sizes)
        E, Z, hid, n = c.behaviour_size, c.stochastic_size, c.hidden_size, c.hidden_layers
        self.uses_portrayal = agent_file.uses_portrayal(variant)
        self.uses_task_state = agent_file.uses_task_state(variant)
        if self.uses_portrayal:
            self.portrayal = MLP(O, c.portrayal_hidden_size, n, D)
        if self.uses_task_state:
            self.task_rnn = nn.GRU(O, c.task_size, batch_first=True)
        if c.phase_input and not self.uses_task_state:
            raise RLAnimateError(f"phase_input needs a task state to give the phase beside: the {variant} variant "
                                 "has none.")
        if c.tempo_input and not c.phase_input:
            raise RLAnimateError("tempo_input needs phase_input: the tempo sits beside the phase.")
        task = agent_file.task_width(c.to_dict(), variant, O)
        head_inputs = (task if self.uses_task_state else 0) + E + Z
        self.behaviour_cell = nn.GRUCell(task + Z + A, E)
        self.prior = MLP(E, hid, n, 2 * Z)
        self.posterior = MLP(E + D, hid, n, 2 * Z)
        self.animation = MLP(head_inputs, hid, n, 2 * A)
        self.decoder = MLP(head_inputs, hid, n, D)

    # --- the models, one frame or a whole sequence at a time -------------------------------------

    def self_description(self, objectives):
        """Portrayal model: (B, T, O) -> (B, T, 42) self-descriptions d_t, or None in single_state."""
        return self.portrayal(objectives) if self.uses_portrayal else None

    def task_features(self, objectives):
        """(B, T, O) -> (B, T, K): the task state h_{1:T} (K = task_size), or o_{1:T} without one."""
        if not self.uses_task_state:
            return objectives
        states, _ = self.task_rnn(objectives)  # h_0 = 0
        return torch.cat([states, self.phase_features(objectives)], -1) if self.config.phase_input else states

    def phase_features(self, objectives):
        """(B, T, O) -> (B, T, 4, or 5 with tempo_input): an oscillating behaviour's phase and second harmonic, then
        its swing rate, zeros for other behaviours (core.spaces.ObjectiveSpace.phase_features, in torch)."""
        signals = objectives[..., spaces.OBJECTIVE_ATTRIBUTES][..., 1:]  # (B, T, 2) A sin, A cos
        sine, cosine = signals.unbind(-1)
        amplitude = torch.clamp(torch.hypot(sine, cosine), min=1e-9)
        features = torch.stack([sine, cosine, 2.0 * sine * cosine / amplitude,
                                (cosine ** 2 - sine ** 2) / amplitude], -1)
        if self.config.tempo_input:
            features = torch.cat([features, swing_rate(sine, cosine)], -1)
        waving = torch.zeros_like(features[..., :1], dtype=torch.bool)
        for name in self.space.oscillating():
            label = objectives.new_tensor(self.space.labels[self.space.names.index(name)])
            waving |= (objectives[..., :self.space.label_size] == label).all(-1, keepdim=True)
        return features * waving

    def transition(self, e_prev, z_prev, a_prev, task):
        """f2: e_{t-1} (B, E), z_{t-1} (B, Z), a_{t-1} (B, 45), h_t (B, K) -> e_t (B, E)."""
        return self.behaviour_cell(torch.cat([task, z_prev, a_prev], -1), e_prev)

    def prior_belief(self, e):
        """p(z_t | e_t): diagonal Gaussian over (..., Z)."""
        return gaussian(*self._gaussian_parameters(self.prior(e)))

    def posterior_belief(self, e, description):
        """q(z_t | e_t, d_t): diagonal Gaussian over (..., Z)."""
        return gaussian(*self.posterior_parameters(e, description))

    def posterior_parameters(self, e, description):
        """(mean, sd), each (..., Z), of q(z_t | e_t, d_t), without building the distribution."""
        return self._gaussian_parameters(self.posterior(torch.cat([e, description], -1)))

    def features(self, task, e, z):
        """What the animation model and the decoder see: (h_t, e_t, z_t), or (e_t, z_t) without a task state."""
        return torch.cat([task, e, z], -1) if self.uses_task_state else torch.cat([e, z], -1)

    def policy(self, features):
        """Animation model: features (..., F) -> Beta over the action (..., 45)."""
        return Independent(Beta(*self.policy_concentrations(features), validate_args=False), 1, validate_args=False)

    def policy_concentrations(self, features: torch.Tensor) -> tuple[torch.Tensor, ...]:
        """The animation model's Beta parameters (alpha, beta), each (..., 45), from features (..., F)."""
        concentrations = self.config.concentration_floor + \
            self.config.concentration_scale * F.softplus(self.animation(features))  # (..., 90)
        return concentrations.chunk(2, -1)

    def decode(self, features):
        """Description decoder: features (..., F) -> predicted real description (..., 42)."""
        return self.decoder(features)

    def _gaussian_parameters(self, out):
        mean, raw_std = out.chunk(2, -1)
        return mean, F.softplus(raw_std) + self.config.min_std

    # --- unrolling -------------------------------------------------------------------------------

    def initial_state(self, batch_size, like):
        """(e_0, z_0, a_0) for `batch_size` sequences, with `like`'s dtype."""
        c = self.config
        return (like.new_zeros(batch_size, c.behaviour_size), like.new_zeros(batch_size, c.stochastic_size),
                like.new_full((batch_size, spaces.ACTION_SIZE), agent_file.INITIAL_ACTION))

    def rollout(self, objectives, deterministic=True, generator=None):
        """Play the agent on objectives (B, T, 7) -> actions (B, T, 45) in [0, 1], without gradients.

        Deterministic: z_t is the posterior mean (the prior mean in single_state) and a_t the Beta
        mean. Otherwise z_t and a_t are sampled; with `generator` (a torch.Generator) the samples
        come from it alone, so a rollout is reproducible from the generator's state.
        """
        with torch.no_grad():
            if deterministic or generator is None:
                return self._rollout(objectives, deterministic)
            seed = int(torch.randint(0, 2 ** 62, (1,), generator=generator))
            with torch.random.fork_rng(devices=[]):
                torch.manual_seed(seed)
                return self._rollout(objectives, deterministic)

    def _rollout(self, objectives, deterministic):
        task = self.task_features(objectives)  # (B, T, K)
        described = self.self_description(objectives)  # (B, T, 42) or None
        e, z, a = self.initial_state(objectives.shape[0], objectives)
        actions = []
        for t in range(objectives.shape[1]):
            e = self.transition(e, z, a, task[:, t])
            belief = self.prior_belief(e) if described is None else self.posterior_belief(e, described[:, t])
            z = belief.mean if deterministic else belief.sample()
            policy = self.policy(self.features(task[:, t], e, z))
            a = policy.mean if deterministic else policy.sample()
            actions.append(a)
        return torch.stack(actions, 1)  # (B, T, 45)

    def observe(self, objectives, previous_actions, conditions):
        """Unroll over a training chunk with given inputs (teacher forcing), sampling z_t ~ q.

        objectives (B, T, 7); previous_actions (B, T, 45), a_{t-1} for each frame; conditions
        (B, T, 42), the d_t the posterior sees. Returns {"features" (B, T, F), "prior", "posterior"
        (Gaussians over (B, T, Z))}.

        Only e_{t-1} and z_{t-1} are recurrent: the parts of f2's input gates that come from h_t and
        a_{t-1}, and of the posterior's first layer that come from d_t, are computed for every frame in
        one product first; the frame-by-frame rest is trainer/agent/unroll.py, whose backward pass is
        written out (the same GRU cell and MLP, at a fraction of autograd's per-operation cost).
        """
        task = self.task_features(objectives)  # (B, T, K)
        cell, (first, *later) = self.behaviour_cell, self.posterior.layers
        sizes = [task.shape[-1], self.config.stochastic_size, previous_actions.shape[-1]]
        weight_task, weight_z, weight_action = cell.weight_ih.split(sizes, 1)
        input_gates = F.linear(torch.cat([task, previous_actions], -1), torch.cat([weight_task, weight_action], 1),
                               cell.bias_ih)  # (B, T, 3E) without z_{t-1}'s part
        weight_e, weight_condition = first.weight.split([self.config.behaviour_size, conditions.shape[-1]], 1)
        posterior_inputs = F.linear(conditions, weight_condition, first.bias)  # (B, T, H) without e_t's part
        # Normal(mean, std).rsample() draw for draw: one (T, B, Z) draw is the T per-frame draws in turn
        noise = objectives.new_empty((objectives.shape[1], objectives.shape[0], sizes[1])).normal_()
        e, z, mean, std = unroll.posterior_unroll(
            input_gates, posterior_inputs, noise, weight_z, cell.weight_hh, cell.bias_hh, weight_e,
            [(layer.weight, layer.bias) for layer in later], self.config.min_std)  # each (B, T, .)
        return {"features": self.features(task, e, z), "prior": self.prior_belief(e), "posterior": gaussian(mean, std)}

    def losses(self, batch, train_config, bounds=None):
        """Per-term scalar losses and their weighted "total" on a batch of chunks (trainer/agent/losses.py);
        `bounds` (45, 2), the action bounds, turn on the pointing term."""
        return loss_terms.agent_losses(self, batch, train_config, bounds)

