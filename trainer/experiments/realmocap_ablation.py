"""What the wave's rhythm at play time, its tempo and the training preset do on real capture: one trained agent
per experiment and preset, its rhythm model's play-time settings varied (`python -m
trainer.scripts.realmocap_ablation`).

Every variant plays an exported agent (runs/realmocap/<experiment>[_<preset>]/agent.npz, trained as
trainer.scripts.realmocap trains it, and reused by it) on each held-out take's own request, and is scored
against that take as trainer.experiments.realmocap scores it (realmocap.compare):
    typical tempo                     seed None as the agent file plays it (core/rhythm.py): the weighted
                                      mean rate, start and stop of the training waves near the request's
                                      exaggeration and near the typical tempo of those, at their weighted
                                      circular mean phase
    mean rhythm, all waves' phase     as files without their waves' phases play: the weighted mean of the
                                      waves near the exaggeration alone (kernel sd 0.05), at the circular
                                      mean phase of all
    ..., the kernels before           the typical tempo with the exaggeration and tempo kernels it had before
                                      BANDWIDTH and TEMPO_BANDWIDTH were chosen on validation takes
    ..., the request's arm's waves    the typical tempo from the training waves of the request's arm alone
    sampled states N                  the typical tempo, the stochastic states sampled with seed N
    seed N                            a seeded draw, as the panel plays a Variation Seed N > 0: one nearby
                                      training wave's rhythm at a random phase, and sampled stochastic states
    tempo asked[, mean rhythm]        the request names the take's own tempo (the panel's Tempo;
                                      baselines.request_tempo), the rest as the typical tempo [mean rhythm]
    preset P[, tempo asked]           the agent trained with another preset (`compare_presets`), as exported
Nearest-clip retrieval from the same training clips is the bar, for the plain request and for the one naming the
tempo. No variant retrains anything. Beside them, OWN_RHYTHM plays each take's own rhythm: not a method (the request
cannot say it), but how much of the agent's gap is its rhythm rather than its poses.
"""
import copy
import time
from collections import defaultdict
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated

import numpy as np

from rlanimate_addon.core import behaviours, spaces
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.rhythm import EARLIER_TEMPO_BANDWIDTH, RhythmModel
from trainer.evaluation import baselines
from trainer.evaluation.rhythm_leave_one_out import swinging_check
from trainer.experiments.options import some_of
from trainer.experiments.realmocap import RealCaptureSettings, compare, real_run, train_real_runs, waves_and_env
from trainer.motion import wave_rhythm
from trainer.motion.fk import ClipReferences
from trainer.motion.realmocap_takes import style_holdout_split, wave_split
from trainer.reporting.plots import wave_hand_paths
from trainer.reporting.realmocap_ablation_report import RETRIEVAL, RETRIEVAL_TEMPO
from trainer.reporting.realmocap_report import seed_summary

#: The experiments of trainer.experiments.realmocap this ablation can run: {name: (split, test set's label)}.
EXPERIMENTS = {"wave": (wave_split, "takes 009-010"), "holdout": (style_holdout_split, "unseen styles")}


@dataclass(frozen=True)
class Variant:
    """A play-time setting of the agent's rhythm model: `bandwidth`, `typical_tempo`, `tempo_bandwidth` and
    `by_arm` as RhythmModel.with_settings takes them (None: the file's); `rhythm_seed` draws the rhythm
    (RhythmModel.draw's seed) and `state_seed` samples the stochastic states (GestureAgent.rollout's), the
    panel's Variation Seed setting both; `tempo`: the request names the take's tempo; `preset`: the agent
    trained with this preset (None: the ablation's own)."""
    name: str
    bandwidth: float | None = None
    typical_tempo: bool | None = None
    tempo_bandwidth: float | None = None
    by_arm: bool | None = None
    rhythm_seed: int | None = None
    state_seed: int | None = None
    tempo: bool = False
    preset: str | None = None


SEEDS = (1, 2, 3)
#: The exaggeration and tempo kernels' sd before they were chosen on validation takes (core/rhythm.py BANDWIDTH,
#: TEMPO_BANDWIDTH): as files made before play.
EARLIER_KERNELS = {"bandwidth": 0.05, "tempo_bandwidth": EARLIER_TEMPO_BANDWIDTH}
VARIANTS = (Variant("typical tempo (as exported)", typical_tempo=True),
            Variant("mean rhythm, all waves' phase", typical_tempo=False, bandwidth=EARLIER_KERNELS["bandwidth"]),
            Variant("typical tempo, the kernels before (sd 0.05, log 1.25)", typical_tempo=True,
                    bandwidth=EARLIER_KERNELS["bandwidth"], tempo_bandwidth=EARLIER_KERNELS["tempo_bandwidth"]),
            Variant("typical tempo, the request's arm's waves", typical_tempo=True, by_arm=True),
            *(Variant(f"sampled states {seed}: typical tempo", typical_tempo=True, state_seed=seed) for seed in SEEDS),
            *(Variant(f"seed {seed}: a nearby wave's rhythm, random phase, sampled states", typical_tempo=True,
                      rhythm_seed=seed, state_seed=seed) for seed in SEEDS),
            Variant("tempo asked: typical-tempo rhythm at the take's tempo", typical_tempo=True, tempo=True),
            Variant("tempo asked, mean rhythm", typical_tempo=False, tempo=True,
                    bandwidth=EARLIER_KERNELS["bandwidth"]))


def preset_variants(preset):
    """The Variants that play the agent trained with another `preset`: as trained, and asked the tempo."""
    return (Variant(f"preset {preset}: as exported", typical_tempo=True, preset=preset),
            Variant(f"preset {preset}, tempo asked", typical_tempo=True, tempo=True, preset=preset))


#: The styles whose first test take (right arm) the hand-path figure shows, per experiment.
PATH_STYLES = {"wave": ("masculine", "youthful", "normal", "active"), "holdout": ("elderly", "exhausted")}
#: The agent as exported, given each held-out take's own rhythm (OwnRhythm).
OWN_RHYTHM = "each take's own rhythm (not a method: the request cannot say it)"


@dataclass(frozen=True)
class AblationSettings(RealCaptureSettings):
    """What the ablation runs: which experiments (EXPERIMENTS), the training seed and length of their agents. A name
    given twice counts once."""
    # which agents to train and play: wave (tested on takes 009-010), holdout (unseen styles)
    experiments: Annotated[tuple[str, ...], some_of(EXPERIMENTS)] = ("wave", "holdout")
    seed: int = 0  # the agents' training seed
    epochs: int = 50  # iterations of Algorithm 1 per agent
    preset: str = "end_chunks"  # the config preset of the agents whose play-time settings vary
    # agents trained with these presets too, played as trained and asked the tempo
    compare_presets: tuple[str, ...] = ("default",)

    def __post_init__(self) -> None:
        unknown = [name for name in self.experiments if name not in EXPERIMENTS]
        if unknown or not self.experiments:
            raise RLAnimateError(f"Unknown real-capture experiment(s) {unknown or '(none)'}: choose from "
                                 f"{', '.join(EXPERIMENTS)}.")
        object.__setattr__(self, "experiments", tuple(dict.fromkeys(self.experiments)))  # frozen: set once, here
        object.__setattr__(self, "compare_presets", tuple(dict.fromkeys(self.compare_presets)))


class VariantMethod:
    """The agent of an AgentMethod playing `model` as its rhythm model, the rhythm drawn with `rhythm_seed` and
    the stochastic states sampled with `state_seed` for every request (baselines.agent_motion; AgentMethod
    gives both one seed)."""

    def __init__(self, method, model, rhythm_seed=None, state_seed=None):
        self.agent = copy.copy(method.agent)
        self.agent.rhythm_model = model
        self.rhythm_seed, self.state_seed = rhythm_seed, state_seed

    def generate(self, behaviour, arm, attributes, frame_count, tempo=None):
        return baselines.agent_motion(self.agent, behaviour, arm, attributes, frame_count, self.rhythm_seed,
                                      self.state_seed, tempo)


class OwnRhythm:
    """The agent of an AgentMethod playing each of `clips` with the rhythm read from that take itself
    (wave_rhythm.clip_signals, as training reads a clip's): what the agent's poses give when its rhythm is right.
    It answers only the requests of `clips`."""

    def __init__(self, method, clips):
        self.agent = method.agent
        self.signals = {self._key(c.arm, c.attributes, len(c.rotvecs)): wave_rhythm.clip_signals(c, len(c.rotvecs))
                        for c in clips}

    @staticmethod
    def _key(arm, attributes, frame_count):
        return arm, float(np.ravel(attributes)[0]), int(frame_count)

    def generate(self, behaviour, arm, attributes, frame_count, tempo=None):
        return baselines.agent_motion(self.agent, behaviour, arm, attributes, frame_count,
                                      rhythm_signals=self.signals[self._key(arm, attributes, frame_count)])


def rhythm_with_phases(model, train_clips):
    """`model` (the agent's RhythmModel) with each training wave's phase: its own, or, for a file exported
    before they were kept, read again from `train_clips` (the waves it was fitted on, in their order),
    which must give the file's examples back."""
    if model.phases is not None:
        return model
    refit = wave_rhythm.fit_rhythm_model([clip for clip in train_clips if clip.declared.oscillates])
    if refit.examples.shape != model.examples.shape or not np.allclose(refit.examples, model.examples):
        raise RLAnimateError("The agent's training waves read differently now than when it was trained: retrain "
                             "it (delete its run folder under runs/realmocap/).")
    return RhythmModel(model.examples, model.phase, model.ramp, model.bandwidth, refit.phases, typical_tempo=False)


def variant_methods(agents, train_clips, variants):
    """{variant name: VariantMethod} for each Variant, of the AgentMethod in `agents` ({preset: AgentMethod}; None
    the ablation's own) it names."""
    models = {preset: rhythm_with_phases(agent.agent.rhythm_model, train_clips) for preset, agent in agents.items()}
    return {v.name: VariantMethod(agents[v.preset], models[v.preset].with_settings(
        v.bandwidth, v.typical_tempo, v.tempo_bandwidth, v.by_arm), v.rhythm_seed, v.state_seed) for v in variants}


def style_phases(read):
    """{style: {phase (circular mean, radians), concentration (its resultant length, 0-1), waves}} of the
    phases at which the training waves that swing start their swing (`read`: wave_rhythm.swinging)."""
    by_style = defaultdict(list)
    for clip, rhythm in read:
        by_style[clip.style].append(rhythm.phase)
    means = {style: np.mean(np.exp(1j * np.array(phases))) for style, phases in by_style.items()}
    return {style: {"phase": float(np.angle(mean)), "concentration": float(abs(mean)), "waves": len(by_style[style])}
            for style, mean in sorted(means.items())}


def rule_checks(read):
    """{rule: rhythm_leave_one_out.leave_one_out} over the training waves that swing (`read`:
    wave_rhythm.swinging), for the typical tempo (as files play it; with the kernels before; from the request's
    arm's waves) and the mean rhythm: the rule judged on training waves alone."""
    return {"typical tempo": swinging_check(read, typical_tempo=True),
            "typical tempo, the kernels before": swinging_check(read, True, **EARLIER_KERNELS),
            "typical tempo, the request's arm's waves": swinging_check(read, True, by_arm=True),
            "mean rhythm": swinging_check(read, typical_tempo=False, bandwidth=EARLIER_KERNELS["bandwidth"])}


def hand_path_panels(methods, clips, styles, env, references):
    """plots.wave_hand_paths panels: per style of `styles`, its first right-arm take of `clips`, the real take
    then each method of `methods` ({label: (method, whether its request names the tempo)})."""
    panels = []
    for style in styles:
        clip = next(c for c in clips if c.style == style and c.arm == "RIGHT")
        answers = {label: spaces.description_joint_positions(env.evaluate(motion).descriptions)
                   for label, motion in ((label, method.generate(behaviours.WAVE, clip.arm, clip.attributes,
                                                                 len(clip.rotvecs),
                                                                 tempo=baselines.request_tempo(clip, with_tempo)))
                                         for label, (method, with_tempo) in methods.items())}
        panels.append((f"{style} {clip.take} right (e = {clip.exaggeration:.2f})", "RIGHT",
                       {"real take": spaces.description_joint_positions(references.get(clip)[0]), **answers}))
    return panels


def run_ablation(settings: AblationSettings) -> dict:
    """Train (or reuse) each experiment's agent and score every variant; the results dict the report writes.
    Draws docs/results/realmocap_ablation_paths.png."""
    waves, env = waves_and_env(settings.realmocap, settings.runs)
    references = ClipReferences(env)
    splits = {name: EXPERIMENTS[name][0](waves) for name in settings.experiments}
    presets: dict[str | None, str] = {None: settings.preset, **{preset: preset for preset in settings.compare_presets}}
    runs = {(name, key): real_run(name, train, test, settings.seed, replace(settings, preset=preset))
            for name, (train, test) in splits.items() for key, preset in presets.items()}
    reports = train_real_runs(runs.values(), workers=settings.workers)
    variants = VARIANTS + tuple(v for preset in settings.compare_presets for v in preset_variants(preset))
    results = {"command": command_line(settings), "seed": settings.seed, "epochs": settings.epochs,
               "preset": settings.preset, "variants": [v.name for v in variants] + [OWN_RHYTHM], "experiments": {}}
    panels = []
    for name, (train, test) in splits.items():
        started = time.process_time()
        agents = {key: baselines.AgentMethod(Path(runs[name, key].settings.output) / "agent.npz") for key in presets}
        methods = variant_methods(agents, train, variants)
        retrieval = baselines.NearestClip(train)
        read = wave_rhythm.swinging([clip for clip in train if clip.declared.oscillates])  # read once
        own = OwnRhythm(agents[None], test)
        scored = {**compare({**{v.name: methods[v.name] for v in variants if not v.tempo}, OWN_RHYTHM: own,
                             RETRIEVAL: retrieval}, test, env, references),
                  **compare({**{v.name: methods[v.name] for v in variants if v.tempo}, RETRIEVAL_TEMPO: retrieval},
                            test, env, references, with_tempo=True)}
        report = reports[runs[name, None].settings.output]
        results["experiments"][name] = {
            "test_set": EXPERIMENTS[name][1], "train_clips": len(train), "test_clips": len(test),
            "train_seconds": report["train_seconds"], "phase_of_all": agents[None].agent.rhythm_model.phase,
            "style_phases": style_phases(read), "rule_checks": rule_checks(read),
            "summaries": {method: seed_summary(scored[method]) for method in results["variants"]
                          + [RETRIEVAL, RETRIEVAL_TEMPO]}}
        shown = {f"{settings.preset}, as exported": (methods[VARIANTS[0].name], False),
                 **{f"{preset}, as exported": (methods[preset_variants(preset)[0].name], False)
                    for preset in settings.compare_presets},
                 f"{settings.preset}, tempo asked": (methods[VARIANTS[-2].name], True),
                 f"{settings.preset}, the take's own rhythm": (own, False),
                 "nearest clip": (retrieval, False), "nearest clip, tempo asked": (retrieval, True)}
        panels += hand_path_panels(shown, test, PATH_STYLES[name], env, references)
        results["experiments"][name]["evaluation_cpu_seconds"] = time.process_time() - started
    Path(settings.results).mkdir(parents=True, exist_ok=True)
    wave_hand_paths(panels, Path(settings.results) / "realmocap_ablation_paths.png")
    return results


def command_line(settings):
    """The command that regenerates these results."""
    return (f"nice -n 10 python -m trainer.scripts.realmocap_ablation --experiments {' '.join(settings.experiments)} "
            f"--seed {settings.seed} --epochs {settings.epochs} --preset {settings.preset} --compare-presets "
            f"{' '.join(settings.compare_presets)}")
