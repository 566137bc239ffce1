"""How near the real-capture agents come to a take they were trained on, against retrieval that may not return
that take (`python -m trainer.scripts.realmocap_ceiling`): where their ceiling lies.

On the test takes 009-010, retrieval asked the tempo finds a take of the same style and session, and the agent
trails it on DTW. Here the wave agents of trainer/experiments/realmocap.py (takes 001-008 and 021-036, trained as
it trains them and reused from its runs) are asked for takes they were trained on, 007-008 of every style and arm
(TRAINED_TAKES), each request as the tests make it (REQUESTS: the label, then the take's tempo too), and retrieval
answers from the other training takes (leave one out: never the take asked for). If the agent trails retrieval
even on takes it has seen, what holds it back is not new takes but what it makes of a request. Beside it, the same
agents and retrieval from every training take on the test takes 009-010. Draws FIGURE: the hand paths of the
trained takes of the styles where the first seed's agent trails retrieval most.
"""
import itertools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rlanimate_addon.core import behaviours, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent.config import PRESETS
from trainer.evaluation import baselines, scoring
from trainer.experiments.realmocap import (
    REQUESTS,
    RealCaptureSettings,
    RealMocapSettings,
    compare,
    real_run,
    train_real_runs,
    waves_and_env,
)
from trainer.experiments.realmocap_model import validation_summary
from trainer.motion.clip import MotionClip
from trainer.motion.fk import ClipReferences
from trainer.motion.realmocap_takes import wave_split
from trainer.reporting.paired import paired_gap
from trainer.reporting.plots import wave_hand_paths

#: The training takes the agents are asked for: the two before the test takes, every style and arm (28).
TRAINED_TAKES = ("007", "008")
#: The hand-path figure, in the results folder, and how many styles it shows.
FIGURE, FIGURE_STYLES = "realmocap_ceiling_paths.png", 3


@dataclass(frozen=True)
class CeilingSettings(RealCaptureSettings):
    """Which wave agents are asked: the real-capture experiments' (trained where their runs lack them)."""
    epochs: int = 100  # iterations of Algorithm 1 per agent, as the real-capture experiments train it
    preset: str = "end_chunks"  # config preset (trainer/agent/config.py)
    seeds: tuple[int, ...] = (0, 1, 2)  # training seeds

    def __post_init__(self):
        if self.preset not in PRESETS or not self.seeds or self.epochs < 1:
            raise RLAnimateError(f"Ceiling: give a preset of {', '.join(PRESETS)} (not {self.preset!r}), at least "
                                 "one seed and at least one epoch.")


def leave_one_out(retrieval: baselines.NearestClip, clips: list[MotionClip], with_tempo: bool) -> list[np.ndarray]:
    """(F_i, 15, 3) `retrieval`'s answer to each clip's request (its tempo too when `with_tempo`) from its clips but
    that clip."""
    tempos, _ = baselines.request_tempos(clips, with_tempo)
    return [retrieval.generate(c.behaviour, c.arm, c.attributes, len(c.rotvecs), tempo=tempo, exclude=c)
            for c, tempo in zip(clips, tempos, strict=True)]


def run_ceiling(settings: CeilingSettings) -> dict:
    """Ask every seed's wave agent and retrieval for the trained and the test takes, both requests; the results
    dict: per set and request, each seed's validation_summary, retrieval's, and the paired gaps."""
    waves, env = waves_and_env(settings.realmocap, settings.runs)
    references = ClipReferences(env)
    train, test = wave_split(waves)
    trained = [c for c in train if c.take in TRAINED_TAKES]
    mocap = RealMocapSettings(epochs=settings.epochs, preset=settings.preset, runs=settings.runs, seeds=settings.seeds)
    runs = {seed: real_run("wave", train, test, seed, mocap) for seed in settings.seeds}
    train_real_runs(runs.values(), workers=settings.workers)
    agents = {seed: baselines.AgentMethod(Path(run.settings.output) / "agent.npz") for seed, run in runs.items()}
    retrieval_method = baselines.NearestClip(train)  # one, so each training take's tempo is read once
    sets = {}
    for (name, clips), (suffix, with_tempo) in itertools.product((("trained", trained), ("test", test)),
                                                                 REQUESTS.items()):
        if name == "trained":
            scored = scoring.score_motions(env, leave_one_out(retrieval_method, clips, with_tempo), clips, references)
        else:
            scored = compare({"r": retrieval_method}, clips, env, references, with_tempo)["r"]
        retrieval = validation_summary(scored)
        by_seed = {str(seed): validation_summary(compare({"a": agent}, clips, env, references, with_tempo)["a"])
                   for seed, agent in agents.items()}
        sets[name + suffix] = {"takes": len(clips), "agents": by_seed, "retrieval": retrieval,
                               "gaps": paired_gaps(by_seed, retrieval)}
    first = agents[settings.seeds[0]]
    Path(settings.results).mkdir(parents=True, exist_ok=True)
    wave_hand_paths(path_panels(first, retrieval_method, trained, trailing_styles(sets["trained_tempo"]), env,
                                references), Path(settings.results) / FIGURE)
    return {"command": command_line(settings), "epochs": settings.epochs, "preset": settings.preset,
            "seeds": list(settings.seeds), "train_takes": len(train), "sets": sets, "figure": FIGURE}


def trailing_styles(entry: dict) -> list[str]:
    """The FIGURE_STYLES styles of a set's entry where the first seed's agent trails retrieval most on DTW."""
    agent = next(iter(entry["agents"].values()))["by_style"]
    retrieval = entry["retrieval"]["by_style"]
    gaps = {style: retrieval[style]["aligned_score"] - agent[style]["aligned_score"] for style in retrieval}
    return sorted(gaps, key=gaps.__getitem__, reverse=True)[:FIGURE_STYLES]


def path_panels(agent: baselines.AgentMethod, retrieval: baselines.NearestClip, trained: list[MotionClip],
                styles: list[str], env, references) -> list:
    """plots.wave_hand_paths panels: per style, its first right-arm trained take, then the agent's answer and
    leave-one-out retrieval's, both asked the take's tempo."""
    panels = []
    for style in styles:
        clip = next(c for c in trained if c.style == style and c.arm == "RIGHT")
        tempo = baselines.request_tempo(clip, True)
        answers = {"RLAnimate (trained on this take)": agent.generate(behaviours.WAVE, clip.arm, clip.attributes,
                                                                      len(clip.rotvecs), tempo=tempo),
                   "retrieval (another take)": leave_one_out(retrieval, [clip], with_tempo=True)[0]}
        panels.append((f"{style} {clip.take} right (e = {clip.exaggeration:.2f}), tempo asked", "RIGHT",
                       {"real take": spaces.description_joint_positions(references.get(clip)[0]),
                        **{label: spaces.description_joint_positions(env.evaluate(motion).descriptions)
                           for label, motion in answers.items()}}))
    return panels


def paired_gaps(by_seed: dict, retrieval: dict) -> dict:
    """{measure: paired_gap} of the agents' per-take scores, the mean over the seeds, against retrieval's."""
    return {measure: paired_gap(np.mean([s["take_scores"][measure] for s in by_seed.values()], axis=0),
                                retrieval["take_scores"][measure])
            for measure in retrieval["take_scores"]}


def command_line(settings: CeilingSettings) -> str:
    """The command that regenerates these results."""
    return (f"nice -n 15 python -m trainer.scripts.realmocap_ceiling --preset {settings.preset} "
            f"--epochs {settings.epochs} --seeds {' '.join(map(str, settings.seeds))}")
