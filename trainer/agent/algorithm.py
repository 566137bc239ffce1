"""Algorithm 1 of the paper: collect a rollout per iteration, then T model updates on buffer chunks.

One iteration (which we count as one epoch, as the paper's Figure 3 does):
    1. draw one training clip at random, or one per behaviour when training both (without
       replacement, in passes over each behaviour's clips);
    2. roll the current agent out on each clip's objectives (from its label and frame count), then
       play every frame through the bpy FK environment in one batch. The agent's inputs are the
       objectives only (it self-describes with its portrayal model), so the whole rollout can be
       computed before the environment is asked for the real descriptions d'_t. Each episode
       (o, a, d', m, FK of m) is appended to the buffer;
    3. run T update steps, each on C random chunks of L frames (beyond two behaviours the config's
       update_steps_many and chunk_count_many: epoch_updates), with Adam on the description, KL and pose
       terms (the paper's L1 + L2 + L3).
Rollouts sample the Beta policy (deterministic=False) with the trainer's own torch generator, so
that they explore and stay reproducible; evaluation rolls out deterministically. With
`average_last_epochs` N, the agent that is evaluated and exported (`played_agent`) is the mean of the
weights after each of the run's last N epochs (stochastic weight averaging, torch.optim.swa_utils);
rollouts keep using the weights being trained.
"""
import math
import time
from typing import TYPE_CHECKING

import numpy as np
import torch
from torch.optim.swa_utils import AveragedModel

from rlanimate_addon.core import behaviours, rhythm, spaces
from trainer.agent import checkpoint, pointing
from trainer.agent.buffer import EpisodeBuffer
from trainer.motion import wave_rhythm
from trainer.motion.clip import trained_behaviours
from trainer.motion.fk import ClipReferences

if TYPE_CHECKING:
    from trainer.agent.config import TrainConfig
    from trainer.agent.models import RLAnimateAgent


def clips_for_behaviour(clips, behaviour, space):
    """Clips grouped as Algorithm 1 draws them: one group per behaviour of the training set `behaviour`
    that `clips` have (trained_behaviours, among the ObjectiveSpace `space`'s), in objective order ([[point
    clips], [wave clips]] for 'both')."""
    wanted = trained_behaviours(clips, behaviour, space.names)
    return [[clip for clip in clips if clip.behaviour == name] for name in wanted]


def chunks_per_update(chunk_count, behaviour_count):
    """Chunks per update step for `behaviour_count` behaviours: the config's `chunk_count` for one or
    two (the paper's), and chunk_count * n / 2 (rounded up) for n > 2. With one random-target set per
    target behaviour (Trainer.collect), each behaviour then gets as many chunks, and as many pointing
    holds, as it gets beside one other: the updates are where it learns, and a fixed batch split four
    ways gave point under half its chunks and its aim went from 0.9 to 3.2 degrees (docs/TRAINING.md)."""
    return int(math.ceil(chunk_count * max(behaviour_count, 2) / 2))


def epoch_updates(config: "TrainConfig", behaviour_count: int) -> tuple[int, int]:
    """(T, C): an iteration's update steps and each step's chunks. For one or two behaviours the config's
    `update_steps` and `chunk_count`; for more, its `update_steps_many` and `chunk_count_many` where given,
    else those and chunks_per_update (docs/TRAINING.md, "The default preset")."""
    steps, chunks = config.update_steps, chunks_per_update(config.chunk_count, behaviour_count)
    if behaviour_count > 2 and config.update_steps_many is not None:
        steps = config.update_steps_many
    if behaviour_count > 2 and config.chunk_count_many is not None:
        chunks = config.chunk_count_many
    return steps, chunks


def clip_objective(space, clip, frame_count=None, rhythm_model=None, with_rhythm=True):
    """(N, O) objectives of the ObjectiveSpace `space` for `clip`'s label, over its own length or
    `frame_count` frames.

    A wave's rhythm (core/rhythm.py) is the clip's own (what the task module knows in training), or,
    given `rhythm_model`, the one it draws for the clip's exaggeration (a request without the clip,
    as the add-on makes); with_rhythm=False gives the paper's wave objective. A clip whose hand does
    not swing gets zero rhythm signals: no swing.
    """
    frames = len(clip.rotvecs) if frame_count is None else frame_count
    signals = None
    if space.behaviour(clip.behaviour).oscillates and with_rhythm:
        signals = (wave_rhythm.clip_signals(clip, frames) if rhythm_model is None
                   else rhythm.signals(rhythm_model.draw(clip.attributes, arm=clip.arm), frames))
    return space.make_objective(clip.behaviour, clip.arm, clip.attributes, frames, signals)


def rollout_actions(agent: "RLAnimateAgent", objectives: list[np.ndarray], deterministic: bool = True,
                    generator: torch.Generator | None = None) -> list[np.ndarray]:
    """A list of (N_i, O) numpy objectives -> the list of (N_i, 45) numpy actions in [0, 1], from one rollout
    of the agent over all of them as a batch (one recurrent step a frame for the batch, not one an episode
    a frame). A rollout is causal, each frame depending on earlier frames only, so a shorter episode is
    padded at its end with its last objective and its actions cut back to its length."""
    longest = max(len(objective) for objective in objectives)
    padded = [np.concatenate([objective, np.repeat(objective[-1:], longest - len(objective), 0)])
              for objective in objectives]
    batch = torch.as_tensor(np.stack(padded), dtype=torch.float32)  # (B, longest, O)
    with torch.no_grad():
        actions = agent.rollout(batch, deterministic=deterministic, generator=generator)  # (B, longest, 45)
    return [action[:len(objective)].double().numpy() for action, objective in zip(actions, objectives, strict=True)]


def gradient_step(agent, optimizer, batch, config, bounds):
    """One update on a batch of chunks: the losses, backward, the gradient clip, an Adam step; returns the losses."""
    losses = agent.losses(batch, config, bounds)
    optimizer.zero_grad(set_to_none=True)
    losses["total"].backward()
    if getattr(config, "grad_clip", None):
        torch.nn.utils.clip_grad_norm_(agent.parameters(), config.grad_clip, foreach=True)
    optimizer.step()
    return losses


class Trainer:
    """Algorithm 1's state (agent, optimiser, buffer, RNGs, epoch, history) and one iteration of it."""

    def __init__(self, agent, env, clips, train_config, behaviour=behaviours.ALL, seed=0,
                 bounds=spaces.DEFAULT_ACTION_BOUNDS, references=None, epochs=None):
        self.agent = agent
        self.env = env
        self.train_config = train_config
        self.behaviour = behaviour
        self.bounds = np.asarray(bounds, dtype=np.float64)
        self.space = agent.space
        self.clip_groups = clips_for_behaviour(clips, behaviour, self.space)
        #: The ids of the behaviours trained, in objective order.
        self.trained = tuple(group[0].behaviour for group in self.clip_groups)
        waves = [clip for group in self.clip_groups for clip in group
                 if self.space.behaviour(clip.behaviour).oscillates]
        #: The training waves' rhythms, from which requests draw theirs (None: the paper's objective).
        self.rhythm_model = None
        if waves and train_config.wave_rhythm:
            self.rhythm_model = wave_rhythm.fit_rhythm_model(waves)
        #: T update steps an iteration of C chunks each: the config's for one or two behaviours, its
        #: "many" ones beyond (epoch_updates).
        self.update_steps, self.chunk_count = epoch_updates(train_config, len(self.clip_groups))
        self.references = references or ClipReferences(env)
        self.optimizer = torch.optim.Adam(agent.parameters(), lr=train_config.learning_rate, foreach=True)
        self.buffer = EpisodeBuffer()
        self.rng = np.random.default_rng(seed)
        self.decks = [[] for _ in self.clip_groups]  # per group: clip indices still to draw this pass
        self.rollout_generator = torch.Generator().manual_seed(seed)
        self.epochs = epochs  # the planned length of the run, for the learning-rate schedule and averaging
        self.averaged = None  # AveragedModel over the last epochs, once averaging has started
        self.epoch = 0
        self.history = []  # one metrics dict per epoch

    def draw(self, group_index):
        """The next clip of a group: clips are drawn at random without replacement, in passes over the
        group, so that every training clip is rolled out once before any is rolled out twice."""
        deck = self.decks[group_index]
        if not deck:
            deck.extend(int(k) for k in self.rng.permutation(len(self.clip_groups[group_index])))
        return self.clip_groups[group_index][deck.pop()]

    def collect(self):
        """Steps 1-2: draw a clip per group, roll the agent out, evaluate all frames in one FK batch.

        With `random_targets`, each iteration also makes that many requests of each target behaviour at
        new targets: a direction drawn uniformly within that behaviour's training clips' range of
        azimuth and elevation, timed like one of its training clips of the same arm (its length and
        hold frames). These episodes have no clip to imitate
        ("imitate" 0); only the pointing term, and the dynamics terms L1 and L2, learn from them:
        the objective is the reward, as the paper's RL framing has it."""
        drawn = [self.draw(k) for k in range(len(self.clip_groups))]
        objectives = [clip_objective(self.space, clip, with_rhythm=self.train_config.wave_rhythm) for clip in drawn]
        imitated = [True] * len(drawn)
        if self.agent.variant != "supervised":
            for group in self._target_groups():
                for _ in range(self.train_config.random_targets):
                    clip = group[int(self.rng.integers(len(group)))]
                    drawn.append(clip)
                    objectives.append(self.space.make_objective(
                        clip.behaviour, clip.arm, self._random_direction(group, clip.arm), len(clip.rotvecs)))
                    imitated.append(False)
        self.agent.eval()
        actions = rollout_actions(self.agent, objectives, deterministic=False, generator=self.rollout_generator)
        rotvecs = spaces.decode_action(np.concatenate(actions), self.bounds)  # (sum F, 15, 3)
        descriptions = np.asarray(self.env.evaluate(rotvecs).descriptions)  # (sum F, 42)
        ends = np.cumsum([len(a) for a in actions])[:-1]
        for clip, objective, imitate, action, description in zip(drawn, objectives, imitated, actions,
                                                                 np.split(descriptions, ends), strict=True):
            motion_description, _ = self.references.get(clip)
            self.buffer.add({
                "objective": objective,
                "action": action,
                "description": description,
                "motion": spaces.encode_action(clip.rotvecs, self.bounds),
                "motion_description": motion_description,
                "hold": (pointing.hold_frames(clip_objective(self.space, clip), motion_description)
                         if clip.behaviour_kind == behaviours.TARGET else np.zeros(len(objective))),
                "imitate": np.full(len(objective), float(imitate)),
            })
        return drawn

    def _target_groups(self):
        """The clip groups of target behaviours, whose requests can aim anywhere."""
        return [group for group in self.clip_groups if group[0].behaviour_kind == behaviours.TARGET]

    def _random_direction(self, group, arm):
        """A unit direction for `arm`, uniform in azimuth and elevation over the range of the arm's
        clips in `group` (one target behaviour's) widened by the config's margin (elevation kept within
        80 degrees)."""
        angles = np.degrees([pointing.azimuth_elevation(arm, clip.attributes) for clip in group if clip.arm == arm])
        margin = self.train_config.random_target_margin_deg
        low = np.maximum(angles.min(axis=0) - margin, (-180.0, -80.0))
        high = np.minimum(angles.max(axis=0) + margin, (180.0, 80.0))
        azimuth, elevation = np.radians(self.rng.uniform(low, high))
        return pointing.direction_from_angles(arm, azimuth, elevation)

    def request_objective(self, clip, frame_count=None):
        """(N, O) objectives of a request like `clip` (its label and length) as the add-on builds
        them: a wave's rhythm is drawn from the training waves', not read from the clip."""
        return clip_objective(self.space, clip, frame_count, self.rhythm_model, self.train_config.wave_rhythm)

    def learning_rate(self):
        """This epoch's Adam step size: cosine from learning_rate down to learning_rate_final over the
        planned epochs, or constant when the config or the trainer gives no final rate or no length."""
        config = self.train_config
        final = config.learning_rate_final
        if final is None or not self.epochs:
            return config.learning_rate
        progress = min(self.epoch / self.epochs, 1.0)
        return final + (config.learning_rate - final) * 0.5 * (1.0 + math.cos(math.pi * progress))

    def update(self):
        """Step 3: T gradient steps on C chunks of L frames; returns each loss's mean over the steps."""
        config = self.train_config
        for group in self.optimizer.param_groups:
            group["lr"] = self.learning_rate()
        self.agent.train()
        totals = {}
        for _ in range(self.update_steps):
            batch = self.buffer.sample_chunks(self.chunk_count, config.chunk_length, self.rng,
                                              config.random_target_weight, config.last_frame_share)
            losses = gradient_step(self.agent, self.optimizer, batch, config, self.bounds)
            for name, value in losses.items():
                totals[name] = totals.get(name, 0.0) + float(value.detach())
        return {name: value / self.update_steps for name, value in totals.items()}

    def run_epoch(self):
        """One iteration of Algorithm 1; appends and returns its metrics."""
        start, cpu_start = time.perf_counter(), time.process_time()
        self.collect()
        collected = time.perf_counter()
        losses = self.update()
        self.epoch += 1
        self._average()
        metrics = {"epoch": self.epoch, "episodes": len(self.buffer), "frames": self.buffer.frames,
                   "learning_rate": self.optimizer.param_groups[0]["lr"], "collect_seconds": collected - start,
                   "update_seconds": time.perf_counter() - collected, "cpu_seconds": time.process_time() - cpu_start,
                   **{f"loss/{name}": value for name, value in losses.items()}}
        self.history.append(metrics)
        return metrics

    def _averaging_window(self):
        """The first epoch whose weights join the average (the run's last N), or None without averaging."""
        last = self.train_config.average_last_epochs
        return self.epochs - last + 1 if last and self.epochs else None

    def _average(self):
        """Add this epoch's weights to the average when the epoch is one of the run's last N."""
        first = self._averaging_window()
        if first is not None and self.epoch >= first:
            if self.averaged is None:
                self.averaged = AveragedModel(self.agent, use_buffers=False)
            self.averaged.update_parameters(self.agent)

    @property
    def played_agent(self):
        """The agent to evaluate and export: the averaged weights when there are any, else the trained ones."""
        return self.agent if self.averaged is None else self.averaged.module

    def state_dict(self):
        return {
            "epoch": self.epoch,
            "agent": self.agent.state_dict(),
            "optimizer": self.optimizer.state_dict(),
            "buffer": self.buffer.state_dict(),
            "history": self.history,
            "decks": [list(deck) for deck in self.decks],
            "rng": checkpoint.capture_rng_states(self.rng, self.rollout_generator),
            "averaged": None if self.averaged is None else self.averaged.state_dict(),
        }

    def load_state_dict(self, state):
        self.epoch = int(state["epoch"])
        self.agent.load_state_dict(state["agent"])
        self.optimizer.load_state_dict(state["optimizer"])
        self.buffer.load_state_dict(state["buffer"])
        self.history = list(state["history"])
        # A checkpoint from before the draws were in passes starts a fresh pass.
        self.decks = [list(deck) for deck in state.get("decks", [[] for _ in self.clip_groups])]
        checkpoint.restore_rng_states(state["rng"], self.rng, self.rollout_generator)
        self.averaged = None
        if state.get("averaged") is not None:
            averaged = AveragedModel(self.agent, use_buffers=False)
            averaged.load_state_dict(state["averaged"])
            # A run extended to more epochs has a later window: an average of the old one is dropped,
            # and the new window's epochs still to come are averaged.
            first = self._averaging_window()
            if first is not None and int(averaged.n_averaged) == self.epoch - first + 1:
                self.averaged = averaged
