"""The behaviour model's unroll over a training chunk, with its backward pass written out.

In a training step the behaviour model (f2's GRU cell, then the posterior MLP and a reparameterised
sample of z_t) steps through the chunk's L frames (trainer/agent/models.py, RLAnimateAgent.observe).
Each frame is some twenty small operations on (C, 64) tensors, and autograd's bookkeeping of them costs
about as much as their arithmetic. `posterior_unroll` is one autograd function instead: the forward
pass runs without recording and keeps what the backward needs, and the backward runs back through the
frames (backpropagation through time) with plain tensor operations, making each weight's gradient in
one matrix product over every frame: an update step takes 0.92x the time (docs/BENCHMARKS.md, "Update
step"). The numbers are those of torch.nn.GRUCell and the MLP, summed in another order
(tests/trainer/agent/test_unroll.py holds them to float64 rounding, gradients included). The task
model's GRU stays torch.nn.GRU, whose own unroll is faster than one written this way.

A GRU step (torch.nn.GRUCell), from the input gates g = W_ih x_t + b_ih (C, 3E) and h_{t-1} (C, E):
    q     = h_{t-1} W_hh^T + b_hh                    (reset, update and new parts, in that order)
    r, u  = sigmoid(g[:2E] + q[:2E])
    n     = tanh(g[2E:] + r * q[2E:])
    h_t   = n + u * (h_{t-1} - n)
The behaviour model's frame t, from e_{t-1} and z_{t-1} (e_0 = z_0 = 0):
    e_t       = GRU step with g = input_gates_t + z_{t-1} W_z^T
    x         = posterior_inputs_t + e_t W_e^T, then x = tanh(x) W_k^T + b_k for each later layer k
    mean, raw = x split in two;  std = softplus(raw) + min_std;  z_t = mean + noise_t * std
"""
from typing import Any

import torch
import torch.nn.functional as F
from torch import Tensor

#: What a GRU step keeps for its backward: r and u (C, 2E), n (C, E) and the new part of q (C, E).
GruKept = tuple[Tensor, Tensor, Tensor]


def posterior_unroll(input_gates: Tensor, posterior_inputs: Tensor, noise: Tensor, weight_z: Tensor, weight_hh: Tensor,
                     bias_hh: Tensor, weight_e: Tensor, later: list[tuple[Tensor, Tensor]],
                     min_std: float) -> tuple[Tensor, Tensor, Tensor, Tensor]:
    """(e (C, L, E), z (C, L, Z), mean (C, L, Z), std (C, L, Z)) of the behaviour model's unroll above.

    input_gates (C, L, 3E): the GRU input gates without z_{t-1}'s part; posterior_inputs (C, L, H): the
    posterior's first layer without e_t's part; noise (L, C, Z): the standard normal draws; weight_z
    (3E, Z) and weight_hh (3E, E), bias_hh (3E,): the GRU cell's; weight_e (H, E): the posterior's first
    layer's for e_t; later: [(weight, bias), ...] of the posterior's later layers.
    """
    flat = [tensor for layer in later for tensor in layer]
    return _PosteriorUnroll.apply(input_gates, posterior_inputs, noise, weight_z, weight_hh, bias_hh, weight_e,
                                  float(min_std), *flat)


def _gru_step(gates_in: Tensor, hidden: Tensor, weight_hh: Tensor, bias_hh: Tensor) -> tuple[Tensor, GruKept]:
    """(h_t, (r and u, n, the new part of q)) of a GRU step: the state and what its backward needs."""
    size = hidden.shape[1]
    gates_hid = torch.addmm(bias_hh, hidden, weight_hh.t())
    rz = torch.sigmoid(gates_in[:, :2 * size] + gates_hid[:, :2 * size])
    new_hid = gates_hid[:, 2 * size:]
    n = torch.tanh(gates_in[:, 2 * size:] + rz[:, :size] * new_hid)
    return n + rz[:, size:] * (hidden - n), (rz, n, new_hid)


def _gru_step_backward(d_hidden: Tensor, hidden_prev: Tensor, kept: GruKept) -> tuple[Tensor, Tensor, Tensor]:
    """(dL/dg, dL/dq, the part of dL/dh_{t-1} that does not pass through q) of a GRU step, from dL/dh_t
    and the step's h_{t-1} and kept values; dL/dh_{t-1} is that part plus dL/dq W_hh."""
    rz, n, new_hid = kept
    size = n.shape[1]
    d_new = d_hidden * (1.0 - rz[:, size:]) * (1.0 - n * n)
    d_rz = torch.cat([d_new * new_hid, d_hidden * (hidden_prev - n)], -1) * rz * (1.0 - rz)
    return torch.cat([d_rz, d_new], -1), torch.cat([d_rz, d_new * rz[:, :size]], -1), d_hidden * rz[:, size:]


def _rows(frames: list[Tensor]) -> Tensor:
    """L per-frame tensors (C, k) -> (L * C, k): every frame's rows, for a gradient summed over frames."""
    return torch.cat(frames, 0)


class _PosteriorUnroll(torch.autograd.Function):
    @staticmethod
    def forward(ctx: Any, input_gates: Tensor, posterior_inputs: Tensor, noise: Tensor, weight_z: Tensor,
                weight_hh: Tensor, bias_hh: Tensor, weight_e: Tensor, min_std: float,
                *flat: Tensor) -> tuple[Tensor, ...]:
        later = list(zip(flat[0::2], flat[1::2], strict=True))
        e = input_gates.new_zeros(input_gates.shape[0], weight_hh.shape[1])
        z = input_gates.new_zeros(input_gates.shape[0], weight_z.shape[1])
        kept: dict[str, list[Any]] = {name: [] for name in ("e", "z", "mean", "std", "gru", "activations", "raw")}
        for t in range(input_gates.shape[1]):
            e, gru = _gru_step(torch.addmm(input_gates[:, t], z, weight_z.t()), e, weight_hh, bias_hh)
            x = torch.addmm(posterior_inputs[:, t], e, weight_e.t())
            activations = []
            for weight, bias in later:
                activations.append(torch.tanh(x))
                x = torch.addmm(bias, activations[-1], weight.t())
            mean, raw = x.chunk(2, -1)
            std = F.softplus(raw) + min_std
            z = mean + noise[t] * std
            for name, value in (("e", e), ("z", z), ("mean", mean), ("std", std), ("gru", gru),
                                ("activations", activations), ("raw", raw)):
                kept[name].append(value)
        ctx.kept = kept
        ctx.save_for_backward(noise, weight_z, weight_hh, weight_e, *flat[0::2])
        return tuple(torch.stack(kept[name], 1) for name in ("e", "z", "mean", "std"))

    @staticmethod
    def backward(ctx: Any, grad_e: Tensor, grad_z: Tensor, grad_mean: Tensor,
                 grad_std: Tensor) -> tuple[Tensor | None, ...]:
        """Back through the frames, last first: each frame's gradients of the GRU's input and hidden gates,
        of the posterior's first layer and of each later layer's output, then every weight's gradient."""
        noise, weight_z, weight_hh, weight_e, *weights = ctx.saved_tensors
        kept = ctx.kept
        e_prev = [torch.zeros_like(kept["e"][0])] + kept["e"][:-1]
        d_in: list[Tensor] = []  # per frame, last first: dL/d input gates (C, 3E)
        d_hid: list[Tensor] = []  # dL/d hidden gates (C, 3E)
        d_first: list[Tensor] = []  # dL/d the posterior's first layer's output (C, H)
        d_layers: list[list[Tensor]] = []  # dL/d each later layer's output
        de_next, dz_next = torch.zeros_like(kept["e"][0]), torch.zeros_like(kept["z"][0])  # from frame t + 1
        for t in reversed(range(len(kept["e"]))):
            dz = grad_z[:, t] + dz_next
            dx = torch.cat([grad_mean[:, t] + dz, (grad_std[:, t] + dz * noise[t]) * torch.sigmoid(kept["raw"][t])], -1)
            d_layers.append([])
            for weight, activation in zip(reversed(weights), reversed(kept["activations"][t]), strict=True):
                d_layers[-1].insert(0, dx)
                dx = (dx @ weight) * (1.0 - activation * activation)
            d_first.append(dx)
            gates_in, gates_hid, d_through = _gru_step_backward(grad_e[:, t] + de_next + dx @ weight_e, e_prev[t],
                                                                kept["gru"][t])
            d_in.append(gates_in)
            d_hid.append(gates_hid)
            de_next, dz_next = d_through + gates_hid @ weight_hh, gates_in @ weight_z
        d_in, d_hid, d_first, d_layers = d_in[::-1], d_hid[::-1], d_first[::-1], d_layers[::-1]
        z_prev = [torch.zeros_like(kept["z"][0])] + kept["z"][:-1]
        later = []
        for k in range(len(weights)):  # each later layer: its weight's and its bias's gradient
            d_out = _rows([frame[k] for frame in d_layers])
            later += [d_out.t() @ _rows([frame[k] for frame in kept["activations"]]), d_out.sum(0)]
        hid_rows = _rows(d_hid)  # (L * C, 3E)
        return (torch.stack(d_in, 1), torch.stack(d_first, 1), None, _rows(d_in).t() @ _rows(z_prev),
                hid_rows.t() @ _rows(e_prev), hid_rows.sum(0), _rows(d_first).t() @ _rows(kept["e"]),
                None, *later)
