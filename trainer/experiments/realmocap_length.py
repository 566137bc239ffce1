"""How long to train on real capture, chosen on validation takes that no test holds
(`python -m trainer.scripts.realmocap_length`).

Two validation experiments stand for the two tests of trainer.experiments.realmocap, from their training
takes only (motion/realmocap_takes.py):
    takes    trained as the wave agent is but for takes 007-008 of the 5 styles the unseen-style test does not
             use, and validated on those (as the wave agent is tested on takes 009-010)
    style    trained on the training takes of 4 styles, validated on takes 001-008 of the fifth, normal (as the
             hold-out agent is tested on 2 styles it never saw)
Each trains one seed's agent for each length from the start (the learning rate decays over the planned
epochs, so a run resumed to a longer length is not the run of that length), scored on its validation takes
(the paper's request, and naming each take's tempo). The chosen length has the best mean of the
score and DTW score over both validation sets for the paper's request (the shorter on a tie). Nearest-clip
retrieval from the same training takes is scored beside it.
"""
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rlanimate_addon.core.errors import RLAnimateError
from trainer.evaluation import baselines
from trainer.experiments.realmocap import (REQUESTS, RealMocapSettings, compare, real_run, train_real_runs,
                                           waves_and_env)
from trainer.motion.fk import ClipReferences
from trainer.motion.realmocap_takes import style_validation_split, take_validation_split
from trainer.paths import REALMOCAP_DIR, REALMOCAP_RUNS, RESULTS_DIR
from trainer.reporting.realmocap_report import seed_summary

#: {name: (split, what it validates)}.
EXPERIMENTS = {"takes": (take_validation_split, "takes 007-008"), "style": (style_validation_split, "style normal")}


@dataclass(frozen=True)
class LengthSettings:
    """What the length search runs: the lengths (epochs, rising), one training seed and preset."""
    lengths: tuple[int, ...] = (50, 100, 200)
    seed: int = 0
    preset: str = "end_chunks"
    realmocap: str = str(REALMOCAP_DIR)
    runs: str = str(REALMOCAP_RUNS)
    results: str = str(RESULTS_DIR)
    workers: int | None = None

    def __post_init__(self):
        if not self.lengths or any(b <= a for a, b in zip(self.lengths, self.lengths[1:])) or self.lengths[0] < 1:
            raise RLAnimateError(f"--lengths {' '.join(map(str, self.lengths))}: give rising epoch counts of at "
                                 f"least 1, such as 50 100 200.")


def choose_length(by_length):
    """The length (a key of `by_length`, {length: {set: seed_summary of the paper's request}}) with the best mean
    score and DTW score over the sets; the shorter on a tie."""
    def merit(summaries):
        return float(np.mean([(s["score"] + s["aligned_score"]) / 2 for s in summaries.values()]))
    return max(sorted(by_length, key=int), key=lambda length: merit(by_length[length]))


def run_lengths(settings: LengthSettings) -> dict:
    """Train each validation experiment's agent for each length and score it; the results dict."""
    waves, env = waves_and_env(settings.realmocap, settings.runs)
    return length_results({name: split(waves) for name, (split, _) in EXPERIMENTS.items()}, settings, env,
                          ClipReferences(env))


def length_results(splits, settings, env, references):
    """run_lengths's results for `splits` ({experiment of EXPERIMENTS: (train, validation) clips})."""
    results = {"command": command_line(settings), "seed": settings.seed, "preset": settings.preset,
               "lengths": list(settings.lengths), "experiments": {}}
    for name, (train, validation) in splits.items():
        retrieval = baselines.NearestClip(train)
        results["experiments"][name] = {
            "validates": EXPERIMENTS[name][1], "train_clips": len(train), "validation_clips": len(validation),
            "retrieval": {suffix or "paper": seed_summary(compare({"r": retrieval}, validation, env, references,
                                                                   with_tempo)["r"])
                          for suffix, with_tempo in REQUESTS.items()}, "by_length": {}}
    runs = {(name, length): real_run(f"{name}_validation_{length}", train, validation, settings.seed,
                                     RealMocapSettings(epochs=length, preset=settings.preset, runs=settings.runs))
            for length in sorted(settings.lengths, reverse=True) for name, (train, validation) in splits.items()}
    reports = train_real_runs(runs.values(), workers=settings.workers)  # the longest first
    for (name, length), run in sorted(runs.items(), key=lambda item: item[0][1]):
        started = time.process_time()
        agent = baselines.AgentMethod(Path(run.settings.output) / "agent.npz")
        validation = splits[name][1]
        results["experiments"][name]["by_length"][str(length)] = {
            "train_cpu_seconds": reports[run.settings.output]["train_cpu_seconds"],
            **{suffix or "paper": seed_summary(compare({"a": agent}, validation, env, references, with_tempo)["a"])
               for suffix, with_tempo in REQUESTS.items()},
            "scoring_cpu_seconds": time.process_time() - started}
    paper = {length: {name: entry["by_length"][str(length)]["paper"]
                      for name, entry in results["experiments"].items()} for length in settings.lengths}
    results["chosen"] = choose_length(paper)
    return results


def command_line(settings):
    """The command that regenerates these results."""
    return (f"nice -n 15 python -m trainer.scripts.realmocap_length --lengths "
            f"{' '.join(map(str, settings.lengths))} --seed {settings.seed} --preset {settings.preset}")
