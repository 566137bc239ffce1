"""The agent at inference, in plain numpy: what Generate Gesture runs inside Blender.

It mirrors `trainer/agent/models.py` (whose docstring has the timing diagram) equation for equation, in
float64 from the file's float32 weights, so its deterministic rollout reproduces the torch agent's
within 1e-5. Work that does not depend on the recurrence (the portrayal model, the task state and
their contributions to each layer) is done for all frames at once before the per-frame loop, and
the rollout runs on one BLAS thread (core/blas_threads.py).

`GestureAgent.rollout(objectives, seed=None)`:
    seed None  the deterministic rollout: z_t is the posterior mean (the prior mean for a
               single_state agent) and a_t the Beta mean;
    seed int   a variation: z_t = mean_t + sd_t * n, a sample of the same Gaussian at every frame,
               with one standard-normal draw n (Z,) for the whole gesture from numpy's
               default_rng(seed), while a_t stays the Beta mean. Drawn once, the noise varies the
               gesture coherently; drawn afresh every frame (z_t or a_t) it only adds jitter.
"""
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from . import agent_file, behaviours, blas_threads, frame_rate, rhythm, spaces
from .errors import RLAnimateError

#: A float64 array: the weights, and every buffer of the rollout.
Array = npt.NDArray[np.float64]
#: [(weight (in, out), bias (out,))] of an MLP (`_mlp_arrays`).
Layers = Sequence[tuple[Array, Array]]
#: (W_ih, W_hh, b_ih, b_hh) of a GRU (`_gru_arrays`).
Gru = tuple[Array, Array, Array, Array]


def load_agent(path: str | Path) -> "GestureAgent":
    """The validated agent file at `path` as a GestureAgent (RLAnimateError if it is unusable)."""
    weights, metadata = agent_file.load_agent_file(path)
    return GestureAgent(weights, metadata)


def _softplus_(x: Array, out: Array) -> Array:
    """softplus(x) = log(1 + e^x) into out."""
    return np.logaddexp(0.0, x, out=out)


def _mlp_arrays(weights: Mapping[str, Array], name: str, layers: int) -> list[tuple[Array, Array]]:
    """[(weight (in, out), bias (out,))] of an MLP: Linear layers with tanh between them."""
    return [(weights[f"{name}.layers.{k}.weight"].T.copy(), weights[f"{name}.layers.{k}.bias"])
            for k in range(layers + 1)]


def _mlp_tail(layers: Layers, x: Array, spare: Array, out: Array) -> Array:
    """An MLP from its first layer's pre-activation x on (tanh, then the remaining Linear layers), in
    preallocated arrays, for one frame (width,) or all (N, width) at once: x and spare, of the hidden
    width, are overwritten; the result goes into out, which is returned."""
    if len(layers) == 1:
        np.copyto(out, x)
        return out
    for weight, bias in layers[1:-1]:
        np.tanh(x, out=x)
        np.dot(x, weight, out=spare)
        spare += bias
        x, spare = spare, x
    np.tanh(x, out=x)
    np.dot(x, layers[-1][0], out=out)
    out += layers[-1][1]
    return out


def _gru_arrays(weights: Mapping[str, Array], name: str, suffix: str = "") -> Gru:
    """(W_ih (in, 3H), W_hh (H, 3H), b_ih, b_hh) of a torch GRU / GRUCell, gates r, z, n, with the r and z
    columns halved: sigmoid(x) = 0.5 (1 + tanh(x / 2)), and halving is exact in floating point, so
    `_gru_stepper` takes tanh of the gates as they come."""
    arrays = (weights[f"{name}.weight_ih{suffix}"].T.copy(), weights[f"{name}.weight_hh{suffix}"].T.copy(),
              weights[f"{name}.bias_ih{suffix}"].copy(), weights[f"{name}.bias_hh{suffix}"].copy())
    for array in arrays:
        array[..., :2 * array.shape[-1] // 3] *= 0.5
    return arrays


def _gru_stepper(h: Array, hidden_gates: Array) -> Callable[[Array, Array], None]:
    """step(input_rz (2H,), input_n (H,)): torch's GRU update h' = (1 - z) n + z h in place on h (H,), from
    W_ih x + b_ih (its r, z and its n parts) and W_hh h + b_hh, written into hidden_gates (3H,) before each
    step (weights from `_gru_arrays`). Scratch arrays and views are made once: the per-frame loops are
    bound by numpy's cost per call, not by arithmetic."""
    H = len(h)
    gates, candidate = np.empty(2 * H), np.empty(H)
    reset, update = gates[:H], gates[H:]
    hidden_rz, hidden_n = hidden_gates[:2 * H], hidden_gates[2 * H:]

    def step(input_rz: Array, input_n: Array) -> None:
        np.add(input_rz, hidden_rz, out=gates)  # halved pre-activations
        np.tanh(gates, out=gates)
        np.add(gates, 1.0, out=gates)
        np.multiply(gates, 0.5, out=gates)  # r, z
        np.multiply(reset, hidden_n, out=candidate)
        np.add(candidate, input_n, out=candidate)
        np.tanh(candidate, out=candidate)  # n
        np.subtract(h, candidate, out=h)
        np.multiply(h, update, out=h)
        np.add(h, candidate, out=h)
    return step


def _gru_sequence(inputs: Array, gru: Gru) -> Array:
    """(N, in) -> (N, H) states of a GRU from h_0 = 0."""
    input_weight, hidden_weight, input_bias, hidden_bias = gru
    input_gates = inputs @ input_weight + input_bias  # (N, 3H)
    H = hidden_weight.shape[0]
    h, hidden_gates = np.zeros(H), np.empty(3 * H)
    step = _gru_stepper(h, hidden_gates)
    states = np.empty((len(inputs), H))
    for input_rz, input_n, state in zip(input_gates[:, :2 * H], input_gates[:, 2 * H:], states, strict=True):
        np.dot(h, hidden_weight, out=hidden_gates)
        hidden_gates += hidden_bias
        step(input_rz, input_n)
        state[...] = h
    return states


class GestureAgent:
    """An exported agent ready to play: `rollout` objectives (N, O) -> actions (N, 45) in [0, 1], O the
    size of the objective `space` its file declares.

    The per-frame loop does one matrix product per input that changes in it (e_t, z_t, a_t): each
    input's weights into every layer it feeds are joined side by side at load time.
    """

    def __init__(self, weights: Mapping[str, ArrayLike], metadata: Mapping[str, Any]) -> None:
        self.metadata = metadata
        self.variant = metadata["variant"]
        self.action_bounds = np.asarray(metadata["action_bounds"], dtype=np.float64)  # (45, 2)
        trained = {b: float(n) for b, n in metadata["average_frames"].items()}
        #: The objective space of the behaviours the file declares (core/spaces.py).
        self.space = agent_file.objective_space(metadata)
        #: The ids of the behaviours the agent was trained for, in objective order.
        self.behaviours = tuple(b for b in self.space.names if b in trained)
        #: Average gesture length in frames per declared behaviour (the UI's default length); one the
        #: agent was not trained for gets the mean of the others, so the UI always has a default.
        self.average_frames = {b: trained.get(b, float(np.mean(list(trained.values()))))
                               for b in self.space.names}
        #: The behaviours whose free arm has no part in them (their training clips leave it still): a gesture of
        #: one holds that arm where it was (core/gesture.py). Files exported before it was kept hold none.
        self.still_free_arm = frozenset(metadata.get("still_free_arm", ()))
        rhythm_values = metadata.get("wave_rhythm")
        #: The training waves' rhythms (core/rhythm.py), or None for an agent trained on the paper's objective.
        self.rhythm_model = None if rhythm_values is None else rhythm.RhythmModel.from_dict(rhythm_values)
        config = metadata["agent_config"]
        w = {name: np.asarray(array, dtype=np.float64) for name, array in weights.items()}
        layers = int(config["hidden_layers"])
        E, Z = int(config["behaviour_size"]), int(config["stochastic_size"])
        self._sizes = (E, Z)
        self._min_std = float(config["min_std"])
        self._floor = float(config["concentration_floor"])
        self._concentration_scale = float(config["concentration_scale"])
        self._uses_portrayal = agent_file.uses_portrayal(self.variant)
        self._uses_task_state = agent_file.uses_task_state(self.variant)
        self._phase_input = bool(config.get("phase_input", False))
        self._tempo_input = bool(config.get("tempo_input", False))
        task_size = agent_file.task_width(config, self.variant, self.space.size)
        if self._uses_portrayal:
            self._portrayal = _mlp_arrays(w, "portrayal", layers)
        if self._uses_task_state:
            self._task_rnn = _gru_arrays(w, "task_rnn", "_l0")
        cell_input, cell_hidden, self._cell_bias, self._cell_hidden_bias = _gru_arrays(w, "behaviour_cell")
        cell_task, cell_z, cell_a = np.split(cell_input, [task_size, task_size + Z])
        # z_t's belief: the posterior (on the self-description) or, in single_state, the prior.
        self._belief = _mlp_arrays(w, "posterior" if self._uses_portrayal else "prior", layers)
        belief_e = self._belief[0][0][:E]
        self._animation = _mlp_arrays(w, "animation", layers)
        animation_blocks = np.split(self._animation[0][0], np.cumsum(
            ([task_size] if self._uses_task_state else []) + [E]))
        animation_e, animation_z = animation_blocks[-2:]
        self._cell_task = cell_task
        self._animation_task = animation_blocks[0] if self._uses_task_state else None
        self._from_e = np.hstack([cell_hidden, belief_e, animation_e])  # (E, 3E + 2 hidden)
        self._from_z = np.hstack([cell_z, animation_z])  # (Z, 3E + hidden)
        self._from_a = cell_a  # (A, 3E)

    def wave_rhythm(self, exaggeration: float, frame_count: int, seed: int | None = None,
                    tempo: float | None = None, arm: str | None = None) -> Array | None:
        """(N, 2) rhythm signals for a wave's objectives (ObjectiveSpace.make_objective), drawn as core/rhythm.py
        says (the training waves' mean for seed None; those of `arm` where the file keeps them) at `tempo` (Hz;
        None: the training waves'), or None for an agent without a rhythm model."""
        if self.rhythm_model is None:
            if tempo is not None:
                raise RLAnimateError("This agent was trained without the waves' rhythm, so it cannot wave at a "
                                     "chosen tempo: set Tempo to 0, or choose an agent trained with it.")
            return None
        if tempo is not None:
            tempo_range = self.tempo_range()
            assert tempo_range is not None  # the agent has a rhythm model
            low, high = tempo_range
            if not low <= float(tempo) <= high:  # also refuses NaN
                raise RLAnimateError(f"A tempo of {float(tempo):.2f} Hz is outside what this agent learned: set "
                                     f"Tempo between {low:.2f} and {high:.2f} Hz, or to 0 to let the agent choose.")
            tempo = float(tempo) / frame_rate.AGENT_FPS
        return rhythm.signals(self.rhythm_model.draw(exaggeration, seed, tempo, arm), frame_count)

    def tempo_range(self) -> tuple[float, float] | None:
        """(slowest, fastest) wave tempo in Hz a request may ask (RhythmModel.tempo_range), or None for an agent
        without a rhythm model."""
        if self.rhythm_model is None:
            return None
        low, high = self.rhythm_model.tempo_range()
        return low * frame_rate.AGENT_FPS, high * frame_rate.AGENT_FPS

    def kind(self, behaviour: str) -> str:
        """The kind of a declared behaviour (behaviours.TARGET or INTENSITY)."""
        return self.space.kind(behaviour)

    def rollout(self, objectives: ArrayLike, seed: int | None = None) -> Array:
        """Objectives (N, O) -> actions (N, 45) in [0, 1]; `seed` as in the module docstring."""
        objectives = np.asarray(objectives, dtype=np.float64)
        if objectives.ndim != 2 or objectives.shape[1] != self.space.size or len(objectives) == 0 \
                or not np.all(np.isfinite(objectives)):
            raise RLAnimateError(f"The agent needs finite objectives of shape (frames, {self.space.size}), got "
                                 f"{objectives.shape}: give the gesture at least one frame and a valid target.")
        if self.space.behaviours_in(objectives) - set(self.behaviours):
            trained = " and ".join(behaviours.key(b) for b in self.behaviours)
            raise RLAnimateError(f"This agent was trained for {trained} "
                                 f"only: choose an agent trained for the requested behaviour in the add-on "
                                 f"preferences.")
        with blas_threads.single_blas_thread():
            noise = None if seed is None else np.random.default_rng(seed).standard_normal(self._sizes[1])  # (Z,)
            return self._rollout(objectives, noise)

    def _task(self, objectives: Array) -> Array:
        """(N, K) what f2 and the heads see of the task: the task state (with the wave's phase features beside it,
        spaces.phase_features, for a phase-input agent), or the objectives without a task state."""
        if not self._uses_task_state:
            return objectives
        task = _gru_sequence(objectives, self._task_rnn)
        if not self._phase_input:
            return task
        return np.hstack([task, self.space.phase_features(objectives, self._tempo_input)])

    def _step_inputs(self, objectives: Array) -> tuple[Array, Array, Array]:
        """(cell (N, 3E), belief (N, hidden), animation (N, hidden)): what each step's GRU cell, belief MLP and
        animation MLP take from the task and the portrayal, precomputed for all N steps at once."""
        E = self._sizes[0]
        count = len(objectives)
        task = self._task(objectives)  # (N, K)
        cell_inputs = task @ self._cell_task + self._cell_bias  # (N, 3E)
        hidden = len(self._belief[0][1])
        belief_inputs = np.broadcast_to(self._belief[0][1], (count, hidden))  # (N, hidden)
        if self._uses_portrayal:
            portrayal = objectives @ self._portrayal[0][0] + self._portrayal[0][1]  # (N, hidden)
            described = _mlp_tail(self._portrayal, portrayal, np.empty_like(portrayal),
                                  np.empty((count, len(self._portrayal[-1][1]))))  # (N, D)
            belief_inputs = belief_inputs + described @ self._belief[0][0][E:]  # (N, hidden)
        animation_inputs = np.broadcast_to(self._animation[0][1], (count, hidden))
        if self._animation_task is not None:  # an agent with a task state
            animation_inputs = animation_inputs + task @ self._animation_task  # (N, hidden)
        return cell_inputs, belief_inputs, animation_inputs

    def _rollout(self, objectives: Array, noise: Array | None) -> Array:
        """Actions (N, 45) of the objectives (N, O), one step per row, in preallocated buffers (views of one
        another: each step writes them in place); noise (Z,) or None as in `rollout`."""
        E, Z = self._sizes
        A = spaces.ACTION_SIZE
        cell_inputs, belief_inputs, animation_inputs = self._step_inputs(objectives)
        hidden = belief_inputs.shape[1]
        gates, belief_end = 3 * E, 3 * E + hidden
        e, input_gates, hidden_gates = np.zeros(E), np.empty(3 * E), self._cell_hidden_bias.copy()  # W_hh e_0 + b_hh
        cell_step = _gru_stepper(e, hidden_gates)
        input_rz, input_n = input_gates[:2 * E], input_gates[2 * E:]
        from_e, from_z = np.empty(self._from_e.shape[1]), np.empty(self._from_z.shape[1])
        e_gates, e_belief, e_animation = from_e[:gates], from_e[gates:belief_end], from_e[belief_end:]
        z_gates, z_animation = from_z[:gates], from_z[gates:]
        from_a = np.full(A, agent_file.INITIAL_ACTION) @ self._from_a  # W_a a_0 (3E,)
        recurrent_gates = from_a.copy()  # W_z z_0 + W_a a_0 with z_0 = 0
        belief_x, animation_x, layer = np.empty(hidden), np.empty(hidden), np.empty(hidden)
        belief, out = np.empty(len(self._belief[-1][1])), np.empty(2 * A)
        mean, spread, z = belief[:Z], belief[Z:], np.empty(Z)
        alpha, beta = out[:A], out[A:]
        belief_layers, animation_layers = self._belief, self._animation
        from_e_weights, from_z_weights, from_a_weights = self._from_e, self._from_z, self._from_a
        hidden_bias, floor = self._cell_hidden_bias, self._floor
        scale, min_std = self._concentration_scale, self._min_std
        actions = np.empty((len(objectives), A))
        for cell_row, belief_row, animation_row, a in zip(
            cell_inputs, belief_inputs, animation_inputs, actions, strict=True
        ):
            np.add(cell_row, recurrent_gates, out=input_gates)
            cell_step(input_rz, input_n)
            np.dot(e, from_e_weights, out=from_e)
            np.add(e_gates, hidden_bias, out=hidden_gates)
            np.add(e_belief, belief_row, out=belief_x)
            _mlp_tail(belief_layers, belief_x, layer, belief)
            if noise is None:
                np.dot(mean, from_z_weights, out=from_z)
            else:
                _softplus_(spread, spread)
                spread += min_std
                spread *= noise
                np.add(mean, spread, out=z)
                np.dot(z, from_z_weights, out=from_z)
            np.add(animation_row, e_animation, out=animation_x)
            animation_x += z_animation
            _mlp_tail(animation_layers, animation_x, layer, out)
            _softplus_(out, out)
            out *= scale
            out += floor  # (90,): alpha, beta
            np.add(alpha, beta, out=a)
            np.divide(alpha, a, out=a)
            np.dot(a, from_a_weights, out=from_a)
            np.add(z_gates, from_a, out=recurrent_gates)
        return actions
