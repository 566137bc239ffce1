"""The agent at inference, in plain numpy: what Generate Gesture runs inside Blender.

It mirrors `trainer/models.py` (whose docstring has the timing diagram) equation for equation, in
float64 from the file's float32 weights, so its deterministic rollout reproduces the torch agent's
within 1e-5. Work that does not depend on the recurrence (the portrayal model, the task state and
their contributions to each layer) is done for all frames at once before the per-frame loop.

`GestureAgent.rollout(objectives, seed=None)`:
    seed None  the deterministic rollout: z_t is the posterior mean (the prior mean for a
               single_state agent) and a_t the Beta mean;
    seed int   a variation: z_t is sampled from the same Gaussian with numpy's default_rng(seed),
               while a_t stays the Beta mean. Sampling the behaviour state varies the gesture
               smoothly through the recurrent state; sampling a_t per frame would only add jitter.
"""
import numpy as np

from . import agent_file, spaces

#: a_0, the previous action of the first frame (trainer/models.py INITIAL_ACTION).
INITIAL_ACTION = 0.5


def load_agent(path):
    """The validated agent file at `path` as a GestureAgent (RLAnimateError if it is unusable)."""
    weights, metadata = agent_file.load_agent_file(path)
    return GestureAgent(weights, metadata)


def _elu(x):
    return np.where(x > 0.0, x, np.expm1(np.minimum(x, 0.0)))


def _softplus(x):
    return np.logaddexp(0.0, x)


def _sigmoid(x):
    return 0.5 * (1.0 + np.tanh(0.5 * x))


class _MLP:
    """Linear layers (weights transposed to (in, out)) with ELU between them; the first layer's
    weight can be split by input blocks so that each block is applied where it is known."""

    def __init__(self, weights, name, layers):
        self.weights = [weights[f"{name}.layers.{k}.weight"].T.copy() for k in range(layers + 1)]
        self.biases = [weights[f"{name}.layers.{k}.bias"] for k in range(layers + 1)]

    def first_blocks(self, sizes):
        """The first layer's weight cut into row blocks of `sizes` (one per concatenated input)."""
        return np.split(self.weights[0], np.cumsum(sizes)[:-1], axis=0)

    def rest(self, first_layer_preactivation):
        x = first_layer_preactivation
        for weight, bias in zip(self.weights[1:], self.biases[1:]):
            x = _elu(x) @ weight + bias
        return x

    def __call__(self, x):
        return self.rest(x @ self.weights[0] + self.biases[0])


class _GRU:
    """torch's GRU cell: gates r, z, n; h' = (1 - z) n + z h."""

    def __init__(self, weights, name, suffix=""):
        self.input_weight = weights[f"{name}.weight_ih{suffix}"].T.copy()  # (in, 3H)
        self.hidden_weight = weights[f"{name}.weight_hh{suffix}"].T.copy()  # (H, 3H)
        self.input_bias = weights[f"{name}.bias_ih{suffix}"]
        self.hidden_bias = weights[f"{name}.bias_hh{suffix}"]
        self.size = self.hidden_weight.shape[0]

    def step(self, input_gates, h):
        """input_gates: W_ih x + b_ih (3H,) for this step; h (H,) -> h' (H,)."""
        H = self.size
        hidden_gates = h @ self.hidden_weight + self.hidden_bias
        reset = _sigmoid(input_gates[:H] + hidden_gates[:H])
        update = _sigmoid(input_gates[H:2 * H] + hidden_gates[H:2 * H])
        candidate = np.tanh(input_gates[2 * H:] + reset * hidden_gates[2 * H:])
        return candidate + update * (h - candidate)

    def sequence(self, inputs):
        """(N, in) -> (N, H), from h_0 = 0."""
        gates = inputs @ self.input_weight + self.input_bias  # (N, 3H)
        h = np.zeros(self.size)
        states = np.empty((len(inputs), self.size))
        for t in range(len(inputs)):
            h = states[t] = self.step(gates[t], h)
        return states


class GestureAgent:
    """An exported agent ready to play: `rollout` objectives (N, 7) -> actions (N, 45) in [0, 1]."""

    def __init__(self, weights, metadata):
        self.metadata = metadata
        self.variant = metadata["variant"]
        self.action_bounds = np.asarray(metadata["action_bounds"], dtype=np.float64)  # (45, 2)
        self.average_frames = {b: float(metadata["average_frames"][b]) for b in spaces.BEHAVIOURS}
        config = metadata["agent_config"]
        self._min_std = float(config["min_std"])
        self._floor = float(config["concentration_floor"])
        self._stochastic_size = int(config["stochastic_size"])
        w = {name: np.asarray(array, dtype=np.float64) for name, array in weights.items()}
        layers = int(config["hidden_layers"])
        self._uses_portrayal = agent_file.uses_portrayal(self.variant)
        self._uses_task_state = agent_file.uses_task_state(self.variant)
        if self._uses_portrayal:
            self._portrayal = _MLP(w, "portrayal", layers)
        if self._uses_task_state:
            self._task_rnn = _GRU(w, "task_rnn", "_l0")
        self._cell = _GRU(w, "behaviour_cell")
        self._prior = _MLP(w, "prior", layers)
        self._posterior = _MLP(w, "posterior", layers)
        self._animation = _MLP(w, "animation", layers)
        E, Z, A = int(config["behaviour_size"]), self._stochastic_size, spaces.ACTION_SIZE
        task = int(config["task_size"]) if self._uses_task_state else spaces.OBJECTIVE_SIZE
        self._cell_task, self._cell_z, self._cell_a = np.split(self._cell.input_weight, [task, task + Z], axis=0)
        self._posterior_e, self._posterior_d = self._posterior.first_blocks([E, spaces.DESCRIPTION_SIZE])
        head = ([task] if self._uses_task_state else []) + [E, Z]
        blocks = self._animation.first_blocks(head)
        self._animation_task = blocks[0] if self._uses_task_state else None
        self._animation_e, self._animation_z = blocks[-2:]

    def rollout(self, objectives, seed=None):
        """Objectives (N, 7) -> actions (N, 45) in [0, 1]; `seed` as in the module docstring."""
        objectives = np.asarray(objectives, dtype=np.float64)
        rng = None if seed is None else np.random.default_rng(seed)
        count, Z = len(objectives), self._stochastic_size
        task = self._task_rnn.sequence(objectives) if self._uses_task_state else objectives  # (N, K)
        cell_inputs = task @ self._cell_task + self._cell.input_bias  # (N, 3E)
        if self._uses_portrayal:
            described = self._portrayal(objectives)  # (N, 42)
            posterior_inputs = described @ self._posterior_d + self._posterior.biases[0]  # (N, hidden)
        animation_inputs = self._animation.biases[0] + (
            task @ self._animation_task if self._uses_task_state else 0.0)  # (N, hidden) or (hidden,)
        animation_inputs = np.broadcast_to(animation_inputs, (count, len(self._animation.biases[0])))
        e = np.zeros(self._cell.size)
        z = np.zeros(Z)
        a = np.full(spaces.ACTION_SIZE, INITIAL_ACTION)
        actions = np.empty((count, spaces.ACTION_SIZE))
        for t in range(count):
            e = self._cell.step(cell_inputs[t] + z @ self._cell_z + a @ self._cell_a, e)
            if self._uses_portrayal:
                belief = self._posterior.rest(e @ self._posterior_e + posterior_inputs[t])
            else:
                belief = self._prior(e)
            z = belief[:Z]
            if rng is not None:
                z = z + (_softplus(belief[Z:]) + self._min_std) * rng.standard_normal(Z)
            out = self._animation.rest(animation_inputs[t] + e @ self._animation_e + z @ self._animation_z)
            alpha = _softplus(out[:spaces.ACTION_SIZE]) + self._floor
            beta = _softplus(out[spaces.ACTION_SIZE:]) + self._floor
            a = actions[t] = alpha / (alpha + beta)
        return actions
