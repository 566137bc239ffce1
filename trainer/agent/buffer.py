"""The episode buffer B of Algorithm 1: whole rollout episodes in, random fixed-length chunks out.

An episode is a mapping of per-frame arrays that share their first (time) axis:
    objective (F, 7), action (F, 45), description (F, 42) (the real d'_t from the FK environment),
    motion (F, 45) (the clip's pose in [0, 1]), motion_description (F, 42) (FK of the clip),
    hold (F,) (1 where the clip holds its point on its objective's ray: trainer/agent/pointing.py),
    imitate (F,) (1 where the episode imitates its clip; 0 for a pointing request at a random target,
    which only borrows a clip's length and hold timing).
`sample_chunks` draws C chunks of L consecutive frames, each from an episode chosen at random (a
random-target episode with `unimitated_weight` times a clip episode's chance), starting at its first
frame with probability FIRST_FRAME_SHARE, ending at its last frame with probability `last_frame_share`
(TrainConfig.last_frame_share), and otherwise at a uniformly random frame, and stacks them
batch-major: (C, L, ...). Uniform starts alone would show the agent a gesture's first frame, where
the unroll starts from a_0 in the middle of every channel, in about one chunk in 85, and its
rollouts started some 20 degrees off the neutral arm. They show its last frame as rarely (one start in
F - L + 1 reaches it, where a middle frame has L), and the last L frames are where a wave's arm comes
down (docs/results/realmocap.md).
"""
import numpy as np
import torch

#: Share of chunks that start at their episode's first frame.
FIRST_FRAME_SHARE = 0.2
EPISODE_KEYS = ("objective", "action", "description", "motion", "motion_description", "hold", "imitate")


class EpisodeBuffer:
    """Stores episodes in order of arrival; unbounded (the paper's runs collect at most a few hundred)."""

    def __init__(self):
        self.episodes = []

    def __len__(self):
        return len(self.episodes)

    @property
    def frames(self):
        return sum(len(e["objective"]) for e in self.episodes)

    def add(self, episode):
        lengths = {key: len(episode[key]) for key in EPISODE_KEYS}
        if len(set(lengths.values())) != 1:
            raise ValueError(f"Episode arrays disagree on their frame count: {lengths}")
        self.episodes.append({key: np.asarray(episode[key], dtype=np.float32) for key in EPISODE_KEYS})

    def sample_chunks(self, count, length, rng, unimitated_weight=1.0, last_frame_share=0.0):
        """`count` chunks of `length` frames as {key: (C, L, ...) float32 tensor}.

        `length` is capped at the shortest episode, so every chunk is whole. Episodes that imitate no
        clip are drawn `unimitated_weight` times as often as those that do. A share `last_frame_share` of
        the chunks ends at the episode's last frame (0: the draws of runs from before it, unchanged). `rng`
        is a numpy Generator, the only source of randomness, so sampling is reproducible.
        """
        if not self.episodes:
            raise ValueError("The episode buffer is empty: collect an episode before sampling.")
        length = min(int(length), min(len(e["objective"]) for e in self.episodes))
        weights = np.array([1.0 if e["imitate"][0] else unimitated_weight for e in self.episodes])
        uniform = np.all(weights == weights[0])  # then the draws of runs from before the weights, unchanged
        picks = rng.choice(len(self.episodes), size=count, p=None if uniform else weights / weights.sum())
        chunks = {key: [] for key in EPISODE_KEYS}
        for index in picks:
            episode = self.episodes[index]
            start = int(rng.integers(0, len(episode["objective"]) - length + 1))
            draw = rng.random()
            if draw < FIRST_FRAME_SHARE:
                start = 0
            elif draw < FIRST_FRAME_SHARE + last_frame_share:
                start = len(episode["objective"]) - length
            for key in EPISODE_KEYS:
                chunks[key].append(episode[key][start:start + length])
        return {key: torch.from_numpy(np.stack(chunks[key])) for key in EPISODE_KEYS}

    def state_dict(self):
        """Tensors only, so a checkpoint loads with torch.load(weights_only=True)."""
        return {"episodes": [{key: torch.from_numpy(e[key]) for key in EPISODE_KEYS} for e in self.episodes]}

    def load_state_dict(self, state):
        self.episodes = [{key: e[key].numpy().copy() for key in EPISODE_KEYS} for e in state["episodes"]]
