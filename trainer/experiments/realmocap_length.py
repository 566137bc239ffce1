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

The play-time rhythm rule is chosen the same way, after the length: the chosen length's agents play the paper's
requests with each exaggeration kernel of `exaggeration_kernels` (core/rhythm.py BANDWIDTH) and tempo kernel of
`tempo_kernels` (TEMPO_BANDWIDTH), from the training waves of both arms and from the request's arm's alone
(BY_ARM), nothing retrained; each rule is also judged on the training waves alone (rhythm_leave_one_out).
"""
import math
import time
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np

from rlanimate_addon.core.errors import RLAnimateError
from trainer.evaluation import baselines
from trainer.evaluation.rhythm_leave_one_out import swinging_check
from trainer.experiments.realmocap import (
    REQUESTS,
    RealCaptureSettings,
    RealMocapSettings,
    compare,
    real_run,
    train_real_runs,
    waves_and_env,
)
from trainer.experiments.realmocap_ablation import VariantMethod
from trainer.motion import wave_rhythm
from trainer.motion.fk import ClipReferences
from trainer.motion.realmocap_takes import style_validation_split, take_validation_split
from trainer.reporting.realmocap_report import seed_summary

#: {name: (split, what it validates)}.
EXPERIMENTS = {"takes": (take_validation_split, "takes 007-008"), "style": (style_validation_split, "style normal")}
#: The exaggeration kernels compared (their sd), and the tempo kernels, each as the rate factor whose logarithm
#: is the kernel's sd in log Hz.
EXAGGERATION_KERNELS = (0.05, 0.1, 0.15)
TEMPO_KERNELS = (1.05, 1.1, 1.15, 1.25)


@dataclass(frozen=True)
class LengthSettings(RealCaptureSettings):
    """What the length search runs: the lengths (epochs, rising), one training seed and preset, and the
    exaggeration and tempo kernels the chosen length's agents play."""
    lengths: tuple[int, ...] = (50, 100, 200)  # epoch counts to compare, rising
    exaggeration_kernels: tuple[float, ...] = EXAGGERATION_KERNELS  # exaggeration kernels (sd) to compare
    # tempo kernels to compare, each the rate factor whose log is its sd in log Hz
    tempo_kernels: tuple[float, ...] = TEMPO_KERNELS
    seed: int = 0  # the agents' training seed
    preset: str = "end_chunks"  # config preset

    def __post_init__(self):
        if (
            not self.lengths
            or any(b <= a for a, b in pairwise(self.lengths))
            or self.lengths[0] < 1
        ):
            raise RLAnimateError(f"--lengths {' '.join(map(str, self.lengths))}: give rising epoch counts of at "
                                 f"least 1, such as 50 100 200.")
        if not self.exaggeration_kernels or min(self.exaggeration_kernels) <= 0:
            raise RLAnimateError(f"--exaggeration-kernels {' '.join(map(str, self.exaggeration_kernels))}: give "
                                 f"positive kernel widths, such as 0.05 0.1.")
        if not self.tempo_kernels or min(self.tempo_kernels) <= 1:
            raise RLAnimateError(f"--tempo-kernels {' '.join(map(str, self.tempo_kernels))}: give rate factors "
                                 f"above 1, such as 1.05 1.1 1.25.")


def choose(candidates):
    """The key of `candidates` ({length or rhythm rule: {set: seed_summary of the paper's request}}, the simpler
    first) with the best mean score and DTW score over the sets; the first on a tie."""
    def merit(summaries):
        return float(np.mean([(s["score"] + s["aligned_score"]) / 2 for s in summaries.values()]))
    return max(candidates, key=lambda key: merit(candidates[key]))


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
    results["chosen"] = choose(paper)
    results["rhythm_rules"] = rhythm_rule_results(splits, runs, results["chosen"], settings.exaggeration_kernels,
                                                  settings.tempo_kernels, env, references)
    results["chosen_rhythm_rule"] = choose({rule: {name: entry["sets"][name]["paper"] for name in splits}
                                            for rule, entry in results["rhythm_rules"].items()})
    return results


def rhythm_rule(bandwidth, factor, by_arm):
    """A rhythm rule's name: its exaggeration and tempo kernels, and whose waves a request weighs."""
    return f"sd {bandwidth}, log {factor}" + (", the request's arm's waves" if by_arm else "")


def rhythm_rule_results(splits, runs, length, bandwidths, factors, env, references):
    """{rule name: {'exaggeration_kernel', 'tempo_kernel': factor, 'by_arm', 'sets': {experiment: {'paper':
    seed_summary, 'leave_one_out': rhythm_leave_one_out.leave_one_out}}}}: the `length` agents of `runs` playing
    the paper's requests with each exaggeration kernel and tempo kernel, from both arms' training waves and from
    the request's arm's, and each rule on the training waves alone."""
    results = {rhythm_rule(bandwidth, factor, by_arm): {"exaggeration_kernel": bandwidth, "tempo_kernel": factor,
                                                        "by_arm": by_arm, "sets": {}}
               for by_arm in (False, True) for bandwidth in bandwidths for factor in factors}
    for name, (train, validation) in splits.items():
        agent = baselines.AgentMethod(Path(runs[name, length].settings.output) / "agent.npz")
        read = wave_rhythm.swinging([clip for clip in train if clip.declared.oscillates])  # read once
        for entry in results.values():
            rule = {"bandwidth": entry["exaggeration_kernel"], "tempo_bandwidth": math.log(entry["tempo_kernel"]),
                    "by_arm": entry["by_arm"]}
            played = VariantMethod(agent, agent.agent.rhythm_model.with_settings(**rule))
            entry["sets"][name] = {
                "paper": seed_summary(compare({"a": played}, validation, env, references)["a"]),
                "leave_one_out": swinging_check(read, True, **rule)}
    return results


def command_line(settings):
    """The command that regenerates these results."""
    return (f"nice -n 15 python -m trainer.scripts.realmocap_length --lengths "
            f"{' '.join(map(str, settings.lengths))} --exaggeration-kernels "
            f"{' '.join(map(str, settings.exaggeration_kernels))} --tempo-kernels "
            f"{' '.join(map(str, settings.tempo_kernels))} "
            f"--seed {settings.seed} --preset {settings.preset}")
