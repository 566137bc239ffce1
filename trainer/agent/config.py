"""Hyperparameters: the agent's sizes (AgentConfig) and Algorithm 1's settings (TrainConfig), with presets.

`load_preset(name)` returns (AgentConfig, TrainConfig) for a name in PRESETS:
    debug    everything tiny, so the whole training loop runs in a test in seconds;
    default  the shipped agent's: every behaviour of the sample library in under 15 CPU minutes on a
             2-core machine (docs/TRAINING.md, "How long training takes"); TrainConfig's defaults;
    paper    the paper gives no sizes; it follows PlaNet (Hafner et al. 2019), so this preset uses
             PlaNet's (200 deterministic / 30 stochastic units, 50 chunks of 50 frames, free nats 3,
             Adam 1e-3, gradient clip 1000). It is slow on a CPU.
    paper_wave_objective, reference_posterior, no_random_targets, no_pointing_term, no_wrist_term
             the default with one of issue 10's choices undone (docs/AGENT.md); reference_posterior
             is meant for the single_state variant (the stochastic behaviour state carries the wave);
    velocity_term, weight_average
             the default plus a pose-velocity term, or with the weights averaged over the last 20
             epochs: tried for the biggest waves' shortfall and for pointing (docs/AGENT.md);
    end_chunks, end_chunks_wide
             the default with a fifth of the chunks ending at the gesture's last frame, where the arm
             comes down (trainer/agent/buffer.py), and that with every state and hidden layer twice as
             wide (real capture: docs/results/realmocap.md, realmocap_ablation.md);
    end_chunks_long, end_chunks_smooth, end_chunks_phase, end_chunks_phase_smooth, end_chunks_tempo_smooth
             end_chunks with chunks of 64 frames (half as many, the same frames an update), so that a
             slow real wave's whole cycle lies in one chunk; or with the pose-velocity term; or with the
             wave's phase and its second harmonic beside the task state, as phase-conditioned motion models
             give it; or with both of the last two; or with those and the wave's swing rate (its tempo) beside
             the phase, as phase-conditioned models give the frequency (real capture's model search:
             docs/results/realmocap_model.md).
Loss terms and their scales are documented in trainer/agent/losses.py and docs/AGENT.md.
"""
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from rlanimate_addon.core.errors import RLAnimateError


@dataclass(frozen=True)
class AgentConfig:
    task_size: int = 64  # h_t, the deterministic task state
    behaviour_size: int = 64  # e_t, the deterministic part of the behaviour state
    stochastic_size: int = 16  # z_t, the stochastic part of the behaviour state
    hidden_size: int = 64  # hidden width of the prior, posterior, animation and decoder MLPs
    portrayal_hidden_size: int = 64  # hidden width of the portrayal MLP
    hidden_layers: int = 2  # hidden layers of every MLP
    min_std: float = 0.1  # floor of the prior's and posterior's standard deviations
    concentration_floor: float = 1.0  # floor of the Beta's alpha and beta (>= 1: unimodal)
    concentration_scale: float = 100.0  # alpha, beta = floor + scale * softplus(output)
    phase_input: bool = False  # f2 and the heads also see the wave's phase and its harmonic (rhythm.phase_features)
    tempo_input: bool = False  # ... and its swing rate (rhythm.swing_rate); needs phase_input

    def to_dict(self):
        """The fields as a dict; phase_input and tempo_input only when on, so that an agent without them is written
        as before."""
        values = asdict(self)
        for flag in ("phase_input", "tempo_input"):
            if not values[flag]:
                del values[flag]
        return values

    @classmethod
    def from_dict(cls, values):
        return cls(**_known_fields(cls, values))


@dataclass(frozen=True)
class TrainConfig:
    """Algorithm 1's settings; the defaults are the default preset's (the shipped agent's)."""
    epochs_single: int = 50  # iterations of Algorithm 1 for one behaviour (the paper's 50)
    epochs_both: int = 100  # ... and for two or more behaviours (the paper's 100)
    update_steps: int = 120  # T: model updates per iteration for one or two behaviours
    update_steps_many: int | None = 99  # T for more than two behaviours (None: update_steps; epoch_updates)
    chunk_count: int = 32  # C: chunks per update for one or two behaviours
    chunk_count_many: int | None = 48  # C for more than two behaviours (None: C * n / 2, chunks_per_update)
    chunk_length: int = 32  # L: frames per chunk
    learning_rate: float = 3e-3  # Adam
    learning_rate_final: float | None = 1e-4  # cosine decay to this over the run's epochs (None: constant)
    grad_clip: float = 100.0  # global gradient-norm clip
    free_nats: float = 1.0  # KL term: KL below this (nats per frame) is not penalised
    kl_balance: float = 0.8  # KL term: weight of the KL's gradient into the prior (1 - it into the posterior)
    huber_delta: float = 0.05  # pose term: Huber threshold, in action units ([0, 1] per channel)
    description_scale: float = 1.0  # the paper's L1: description reconstruction (MSE, summed over the 42 numbers)
    kl_scale: float = 0.1  # the paper's L2: KL(q || p)
    pose_scale: float = 100.0  # the paper's L3: Huber to the clip's pose, summed over the 45 channels
    velocity_scale: float = 0.0  # Huber of the pose's frame-to-frame change to the clip's (0: off)
    wrist_scale: float = 1000.0  # squared distance (m^2) of the waving wrist to the clip's (0: off)
    portrayal_direct_loss: bool = True  # also fit the self-description to the clip's description
    portrayal_scale: float = 1.0  # ... with this scale (MSE, summed over the 42 numbers)
    random_targets: int = 3  # requests at random targets per iteration and target behaviour (pointing term only)
    random_target_margin_deg: float = 20.0  # random directions reach this far past the clips' azimuth and elevation
    random_target_weight: float = 1 / 3  # a random-target episode's chance in the update batch, relative to a clip's
    pointing_scale: float = 100.0  # the finger line against the objective's ray at the hold (squared radians)
    policy_scale: float = 0.01  # Beta concentrations fitted by NLL of the clip's pose (mean detached)
    posterior_on_reference: bool = False  # single_state: condition the posterior on the clip's description
    wave_rhythm: bool = True  # waves' objectives carry their rhythm (core/rhythm.py); False: the paper's
    average_last_epochs: int = 0  # play and export the mean of the weights after each of the last N epochs (0: off)
    last_frame_share: float = 0.0  # share of chunks that end at their episode's last frame (buffer.py; 0: off)

    def to_dict(self):
        return asdict(self)

    @classmethod
    def from_dict(cls, values):
        return cls(**_known_fields(cls, values))


def _known_fields(cls, values):
    names = {f.name for f in fields(cls)}
    return {key: value for key, value in dict(values).items() if key in names}


_DEFAULT_TRAIN = TrainConfig()
#: What the debug and paper presets keep of the first defaults (issue 10 and 27's choices came after them).
_FIRST_TRAIN: dict[str, Any] = dict(update_steps_many=None, chunk_count_many=None, learning_rate=1e-3,
                                    learning_rate_final=None, wrist_scale=0.0, random_targets=1,
                                    random_target_margin_deg=0.0, random_target_weight=1.0)
PRESETS = {
    "debug": (
        AgentConfig(task_size=8, behaviour_size=8, stochastic_size=4, hidden_size=8,
                    portrayal_hidden_size=8, hidden_layers=1),
        TrainConfig(epochs_single=2, epochs_both=2, update_steps=3, chunk_count=4, chunk_length=8, **_FIRST_TRAIN),
    ),
    "default": (AgentConfig(), _DEFAULT_TRAIN),
    # Ablations of issue 10's choices (docs/AGENT.md, "Waving, pointing, raising"), each the default but:
    "paper_wave_objective": (AgentConfig(), replace(_DEFAULT_TRAIN, wave_rhythm=False)),  # no rhythm in waves
    "reference_posterior": (AgentConfig(), replace(_DEFAULT_TRAIN, wave_rhythm=False, posterior_on_reference=True)),
    "no_random_targets": (AgentConfig(), replace(_DEFAULT_TRAIN, random_targets=0)),
    "no_pointing_term": (AgentConfig(), replace(_DEFAULT_TRAIN, random_targets=0, pointing_scale=0.0)),
    "velocity_term": (AgentConfig(), replace(_DEFAULT_TRAIN, velocity_scale=500.0)),
    "weight_average": (AgentConfig(), replace(_DEFAULT_TRAIN, average_last_epochs=20)),
    "no_wrist_term": (AgentConfig(), replace(_DEFAULT_TRAIN, wrist_scale=0.0)),
    # Issue 26's: a fifth of the chunks end at the gesture's end, where the arm comes down (real capture).
    "end_chunks": (AgentConfig(), replace(_DEFAULT_TRAIN, last_frame_share=0.2)),
    "end_chunks_wide": (AgentConfig(task_size=128, behaviour_size=128, hidden_size=128, portrayal_hidden_size=128),
                        replace(_DEFAULT_TRAIN, last_frame_share=0.2)),  # ... and twice the width (capacity)
    # Issue 45's model search on real capture (options: no other preset changes).
    "end_chunks_long": (AgentConfig(), replace(_DEFAULT_TRAIN, last_frame_share=0.2, chunk_length=64, chunk_count=16)),
    "end_chunks_smooth": (AgentConfig(), replace(_DEFAULT_TRAIN, last_frame_share=0.2, velocity_scale=500.0)),
    "end_chunks_phase": (AgentConfig(phase_input=True), replace(_DEFAULT_TRAIN, last_frame_share=0.2)),
    "end_chunks_phase_smooth": (AgentConfig(phase_input=True),
                                replace(_DEFAULT_TRAIN, last_frame_share=0.2, velocity_scale=500.0)),
    "end_chunks_tempo_smooth": (AgentConfig(phase_input=True, tempo_input=True),
                                replace(_DEFAULT_TRAIN, last_frame_share=0.2, velocity_scale=500.0)),
    "paper": (
        AgentConfig(task_size=200, behaviour_size=200, stochastic_size=30, hidden_size=200,
                    portrayal_hidden_size=200),
        TrainConfig(update_steps=100, chunk_count=50, chunk_length=50, grad_clip=1000.0, free_nats=3.0, **_FIRST_TRAIN),
    ),
}


def load_preset(name):
    """(AgentConfig, TrainConfig) of the preset `name`."""
    if name not in PRESETS:
        raise RLAnimateError(f"Unknown config preset {name!r}: use one of {', '.join(PRESETS)}.")
    return PRESETS[name]
