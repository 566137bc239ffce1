"""Learn from real motion capture (Bandai Namco Research, CC BY-NC 4.0) and compare with the baselines
(`python -m trainer.scripts.realmocap`).

The clips are read from ../shared/realmocap/ beside the repository (never copied into it; see
docs/REALMOCAP.md). Each BVH goes through trainer/blender_io/clip_import.py (Blender's BVH importer and
the canonicalisation); the capture has no fingers, so the synthesised clips' relaxed hand (motion/realmocap_takes.py)
is put on, and labels come from the motion (trainer/motion/autolabel.py).

Experiments, each seed's agent trained as a Ray task (trainer/cluster.py; `train_real`: the worker builds the
session of real clips from the import cache and runs trainer.experiments.run.train) into runs/realmocap/<name>/
(<name>_<preset>/ for a preset other than default), and runs/realmocap_seed<N>/ for each further seed:
    wave      wave agent on takes 001-008 and 021-036 of the 7 styles x 2 arms (249 clips), tested on takes
              009-010 (28) and on the 14 goodbye waves of dataset 1 (other actor takes, other styles)
    holdout   the same on every take of 5 styles, tested on takes 001-010 of the 2 unseen styles (40 clips)
    guide     the right-arm directing gestures as pointing: the pointing agent is given the direction
              in which the actor held the arm, and we report the angle between the generated and the
              real forearm (elbow -> wrist) at each one's hold
Takes 011-020 are never read (motion/realmocap_takes.py, WITHHELD_TAKES). Every test take's request is answered
twice (REQUESTS): with its auto-label and length, and naming its wave's tempo as well. Both baselines
(trainer/evaluation/baselines.py) answer the same requests, retrieval from the same training clips; the
agents are scored through their exported agent.npz (the numpy runtime the add-on plays). The first seed's
agents give the full tables and the figure; every seed's agents are scored on the wave sets ("seeds"). What tempo a
request's label can reach on each test, from the training waves alone, is read beside them
(trainer/evaluation/label_reach.py).
Writes docs/results/realmocap.json and .md, the real-data section of docs/results/baselines.json and .md,
and docs/results/realmocap_frames.png (generated and real frames side by side).
"""
import functools
import itertools
import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from rlanimate_addon.core import behaviour_metrics, behaviours, skeleton, spaces
from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent import checkpoint
from trainer.blender_io.clip_import import EXPECTED_FPS, import_clip
from trainer.blender_io.clip_session import LibrarySession
from trainer.blender_io.fk_env import FKEnvironment
from trainer.blender_io.import_worker import import_into_cache
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.blender_io.rig_session import blender_output, new_empty_scene
from trainer.cluster import connect, run_tasks
from trainer.evaluation import baselines, scoring
from trainer.evaluation.label_reach import label_reach
from trainer.experiments.options import require_values
from trainer.experiments.run import RunSettings, is_finished, train_logged, train_runs
from trainer.motion import autolabel, wave_rhythm
from trainer.motion.fk import ClipReferences
from trainer.motion.hands import relaxed_hand
from trainer.motion.realmocap_takes import (
    GUIDE_TARGET_DISTANCE,
    HOLDOUT_STYLES,
    PAPER_LABELS,
    TAKE_GROUPS,
    parse_name,
    require_realmocap,
    style_holdout_split,
    take_group,
    take_paths,
    wave_split,
)
from trainer.paths import (
    DEFAULT_MANIFEST,
    INSTALLED_AGENT,
    REALMOCAP_DIR,
    REALMOCAP_RUNS,
    RESULTS_DIR,
    seed_folder,
    shown,
)
from trainer.reporting.realmocap_report import frames_figure, seed_summary


def import_real_clip(path, cache_dir=REALMOCAP_RUNS / "import_cache", labels=PAPER_LABELS):
    """A real clip on the canonical rig with a relaxed hand and labels derived from its motion.

    `labels` ({folder: Behaviour}, realmocap_takes.PAPER_LABELS or GESTURE_LABELS) says what the take
    performs: an intensity behaviour's arm and exaggeration come from autolabel.label_wave, a target
    behaviour's arm and held direction from autolabel.label_point (and, beside point, a target
    GUIDE_TARGET_DISTANCE along it). `.style` and `.take` come from the name.
    """
    info = parse_name(path)
    clip = relaxed_hand(import_clip(path, cache_dir=cache_dir))
    behaviour = labels[info["content"]]
    autolabel.label_clip(clip, behaviours.POINT if behaviour.kind == behaviours.TARGET else behaviours.WAVE)
    if behaviour.name not in behaviours.KNOWN_KINDS:
        clip.behaviour, clip.kind = behaviour.name, behaviour.kind
        if behaviour.kind == behaviours.TARGET:
            clip.target = tuple(skeleton.shoulder_rest_position(clip.arm) + GUIDE_TARGET_DISTANCE * clip.attributes)
    clip.content, clip.style, clip.take, clip.named_arm = info["content"], info["style"], info["take"], info["arm"]
    return clip


def load_folder(folder, root=REALMOCAP_DIR, cache_dir=REALMOCAP_RUNS / "import_cache", import_workers=1,
                labels=PAPER_LABELS):
    """Every clip of root/folder ('wave', 'bye' or 'guide') but the withheld takes, sorted by name, labelled
    as `labels` says (import_real_clip); import_workers > 1: the takes the cache lacks are imported by that
    many import workers first (import_worker.import_into_cache)."""
    paths = take_paths(require_realmocap(root) / folder)
    if import_workers > 1:
        import_into_cache([(p, EXPECTED_FPS) for p in paths], Path(cache_dir), import_workers)
    return [import_real_clip(p, cache_dir, labels) for p in paths]


def waves_and_env(realmocap=REALMOCAP_DIR, runs=REALMOCAP_RUNS):
    """(waves, env): the one-arm waves under `realmocap` (load_folder, through <runs>/import_cache) and an FK
    environment, in a fresh scene with one torch thread: what the wave experiments score in."""
    torch.set_num_threads(1)
    new_empty_scene()
    root = require_realmocap(realmocap)
    with blender_output():
        waves = load_folder("wave", root, Path(runs) / "import_cache")
        env = FKEnvironment()
    return waves, env


class RealSession:
    """What trainer.experiments.run.train needs (env, references, train_clips, test_clips, problems), over real clips
    (every one imported: a take that does not import stops the experiment)."""

    def __init__(self, env, references, train_clips, test_clips):
        self.env, self.references, self.problems = env, references, []
        for split, clips in (("train", train_clips), ("test", test_clips)):
            for clip in clips:
                clip.split = split
        self.train_clips, self.test_clips = list(train_clips), list(test_clips)


def forearm_direction(bone_heads, bone_names, arm):
    """(F, 3) unit elbow -> wrist vectors from FKResult.bone_heads."""
    side = skeleton.ARM_PREFIX[arm]
    elbow = bone_heads[:, bone_names.index(side + "ForeArm")]
    wrist = bone_heads[:, bone_names.index(side + "Hand")]
    vectors = wrist - elbow
    return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


def angle_degrees(a, b):
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0))))


def guide_angles(method, clips, env):
    """Per guide clip: the angle (deg) between generated and real forearm directions at their holds."""
    rows = []
    motions = baselines.generate_for(method, clips)
    for clip, motion in zip(clips, motions, strict=True):
        real = env.evaluate(clip.rotvecs)
        generated = env.evaluate(motion)
        hold = autolabel.label_point(motion, clip.arm).hold_frame
        real_forearm = forearm_direction(real.bone_heads, env.bone_names, clip.arm)[clip.label.hold_frame]
        generated_forearm = forearm_direction(generated.bone_heads, env.bone_names, clip.arm)[hold]
        rows.append({"name": clip.name, "style": clip.style, "arm": clip.arm,
                     "direction": [round(float(v), 4) for v in clip.attributes],
                     "forearm_angle_deg": angle_degrees(real_forearm, generated_forearm)})
    return {"mean_forearm_angle_deg": float(np.mean([r["forearm_angle_deg"] for r in rows])),
            "median_forearm_angle_deg": float(np.median([r["forearm_angle_deg"] for r in rows])), "clips": rows}


@dataclass(frozen=True)
class RealRun:
    """One training run on real takes, as a Ray task gets it: its settings, the takes (BVH paths, in
    the session's order) its worker reads from the import cache, and what each folder's takes perform
    (import_real_clip's `labels`)."""
    settings: RunSettings
    train_takes: tuple[str, ...]
    test_takes: tuple[str, ...]
    cache: str
    labels: dict = field(default_factory=lambda: PAPER_LABELS)


def real_run(name, train_clips, test_clips, seed, settings, labels=PAPER_LABELS, training_set=behaviours.WAVE):
    """The RealRun of experiment `name` ('wave', 'holdout', 'gestures') with `seed`, training the behaviours
    `training_set` names (behaviours.training_set), into <runs>[_seed<N>]/<name>/ for the default preset and
    <name>_<preset>/ for another (resumed when a checkpoint is there)."""
    output = seed_folder(settings.runs, seed) / (name if settings.preset == "default" else f"{name}_{settings.preset}")
    run = RunSettings(output=str(output), behaviour=behaviours.key(training_set), clips=f"realmocap:{name}",
                      epochs=settings.epochs, seed=seed, preset=settings.preset, variant="rlanimate", eval_every=0,
                      resume=(output / checkpoint.FILENAME).is_file(), progress=False)
    return RealRun(run, tuple(c.source for c in train_clips), tuple(c.source for c in test_clips),
                   str(Path(settings.runs) / "import_cache"), labels)


def real_session(train_takes, test_takes, cache, labels=PAPER_LABELS):
    """A RealSession of the takes, imported (or read from the cache `cache`) in this process's Blender and
    labelled as `labels` says."""
    new_empty_scene()
    with blender_output():
        train_clips, test_clips = ([import_real_clip(path, cache, labels) for path in paths]
                                   for paths in (train_takes, test_takes))
        env = FKEnvironment()
    return RealSession(env, ClipReferences(env), train_clips, test_clips)


def train_real(run: RealRun) -> dict:
    """Train `run` on a session its own process builds, its output in train.log; the report. A Ray task:
    pinned to one torch thread, it is bit for bit the run `train` makes on the same takes in this process."""
    return train_logged(run.settings,
                        functools.partial(real_session, run.train_takes, run.test_takes, run.cache, run.labels))


def train_real_runs(runs, address=None, workers=None):
    """Train the unfinished RealRuns as Ray tasks (trainer/cluster.py); {output folder: its report.json}
    of every run."""
    pending = [run for run in runs if not is_finished(Path(run.settings.output), run.settings.epochs)]
    if pending:
        connect(address, workers)
        for run, _ in run_tasks(train_real, pending, name=lambda run: f"The run in {run.settings.output}"):
            print(f"realmocap: trained {shown(run.settings.output)}", flush=True)
    return {run.settings.output: json.loads((Path(run.settings.output) / "report.json").read_text()) for run in runs}


#: The requests every method answers, by the suffix of their result keys: the paper's (each take's auto-label
#: and length), and the same naming the wave's own tempo (baselines.request_tempo; the panel's Tempo).
REQUESTS = {"": False, "_tempo": True}


def compare(methods, clips, env, references, with_tempo=False):
    """{method: scoring.score_motions result} on `clips`, each answering the clip's request (with its tempo when
    `with_tempo`, and `tempo_fallbacks` {take: why} naming the takes whose request fell back to the label,
    baselines.request_tempos); for waves also `label_error`, the mean |autolabel exaggeration of the generated wave -
    requested exaggeration| (does it portray the label?)."""
    results = {}
    tempos, fallbacks = baselines.request_tempos(clips, with_tempo)  # read once for every method
    for name, method in methods.items():
        motions = baselines.generate_at(method, clips, tempos)
        result = scoring.score_motions(env, motions, clips, references)
        if all(c.declared.oscillates for c in clips):
            result["label_error"] = float(np.mean([abs(autolabel.label_wave(m).exaggeration - c.exaggeration)
                                                   for m, c in zip(motions, clips, strict=True)]))
        if fallbacks:
            result["tempo_fallbacks"] = fallbacks
        results[name] = result
    return results


def label_table(clips):
    """{style: {arm: mean exaggeration}} and per-style elevation/stroke means, for the report."""
    table = {}
    for clip in clips:
        entry = table.setdefault(clip.style, {"exaggeration": [], "elevation": [], "stroke": [], "arm_correct": []})
        entry["exaggeration"].append(clip.exaggeration)
        entry["elevation"].append(clip.label.elevation)
        entry["stroke"].append(clip.label.stroke)
        entry["arm_correct"].append(clip.named_arm is None or clip.named_arm == clip.arm)
    return {
        style: {
            "clips": len(v["exaggeration"]),
            "exaggeration": float(np.mean(v["exaggeration"])),
            "exaggeration_sd": float(np.std(v["exaggeration"])),
            "elevation_deg": float(np.mean(v["elevation"])),
            "stroke_arm_lengths": float(np.mean(v["stroke"])),
            "arm_correct": int(np.sum(v["arm_correct"])),
        }
        for style, v in sorted(table.items(), key=lambda item: np.mean(item[1]["exaggeration"]))
    }


def tempo_table(clips, references):
    """{style: {takes, spectrum_hz, strokes_hz, stroke_cm, by_takes}} over wave clips: the median tempo of a style's
    takes as the trainer reads it (the peak of the swing's spectrum, wave_rhythm.clip_tempo; a request's Tempo) and
    as the report's stroke count reads it (core.behaviour_metrics.wave_measures, whose frequency ratio the bars
    judge), and the median stroke between turning points; `by_takes` {group of realmocap_takes.TAKE_GROUPS:
    {takes, exaggeration (mean), spectrum_hz}}, the label and tempo of each group of takes the style has. A take
    neither reads a tempo in is left out of that median."""
    readings = {}
    for clip in clips:
        measures = behaviour_metrics.wave_measures(spaces.description_joint_positions(references.get(clip)[0]),
                                                   clip.arm)
        spectrum = wave_rhythm.tempo_reading(clip)[0]
        entry = readings.setdefault(clip.style, {"spectrum": [], "strokes": [], "stroke": [], "groups": []})
        entry["spectrum"].append(np.nan if spectrum is None else spectrum)
        entry["strokes"].append(measures["frequency"] or np.nan)
        entry["stroke"].append(100.0 * measures["swing"])
        entry["groups"].append((take_group(clip.take), clip.exaggeration, entry["spectrum"][-1]))
    return {style: {"takes": len(entry["spectrum"]), "spectrum_hz": float(np.nanmedian(entry["spectrum"])),
                    "strokes_hz": float(np.nanmedian(entry["strokes"])),
                    "stroke_cm": float(np.median(entry["stroke"])), "by_takes": _by_take_group(entry["groups"])}
            for style, entry in sorted(readings.items())}


def _by_take_group(readings):
    """{group: {takes, exaggeration, spectrum_hz}} of [(group, exaggeration, spectrum tempo)], in TAKE_GROUPS order."""
    table = {}
    for group in TAKE_GROUPS:
        rows = np.array([(e, hz) for name, e, hz in readings if name == group]).reshape(-1, 2)
        if len(rows):
            table[group] = {"takes": len(rows), "exaggeration": float(rows[:, 0].mean()),
                            "spectrum_hz": float(np.nanmedian(rows[:, 1])) if np.isfinite(rows[:, 1]).any() else None}
    return table


def point_agent_and_library(point_agent, runs, epochs, seed):
    """(AgentMethod, sample-library point training clips) for the guide experiment.

    `point_agent` None: the add-on's installed default agent when it is trained, else a point agent
    trained here on the sample library (runs/realmocap/sample_point/)."""
    library = LibrarySession(DEFAULT_MANIFEST)
    clips = [c for c in library.train_clips if c.declared.aims]
    if point_agent is None:
        try:
            installed = baselines.AgentMethod(INSTALLED_AGENT)
            training = installed.agent.metadata.get("training", {})
            if not training.get("untrained") and behaviours.POINT in installed.agent.behaviours:
                return installed, clips
        except RLAnimateError as error:
            print(f"realmocap: not using the installed agent: {error}", file=sys.stderr)
        output = Path(runs) / "sample_point"
        if not is_finished(output, epochs):
            list(train_runs([RunSettings(output=str(output), behaviour=behaviours.key(behaviours.POINT),
                                         clips=str(DEFAULT_MANIFEST), epochs=epochs, seed=seed, preset="default",
                                         variant="rlanimate", eval_every=0,
                                         resume=(output / checkpoint.FILENAME).is_file(), progress=False)]))
        point_agent = output / "agent.npz"
    return baselines.AgentMethod(point_agent), clips


def _summary(result):
    return {"clips": len(result["clips"]),
            **{key: result[key] for key in ("score", "smoothness", "label_error") if key in result}}


@dataclass(frozen=True)
class RealCaptureSettings:
    """What every real-capture experiment's settings have: the capture, its runs and results, and how many of its
    training runs at a time."""
    realmocap: str = str(REALMOCAP_DIR)  # the capture's folder (wave/, bye/, guide/)
    runs: str = str(REALMOCAP_RUNS)  # seed 0's runs and the import cache; seed N's go to <runs>_seed<N>
    results: str = str(RESULTS_DIR)  # where the results go: JSON, a Markdown page and figures
    workers: int | None = None  # a local Ray's training runs at a time (None: one per CPU)


@dataclass(frozen=True)
class RealMocapSettings(RealCaptureSettings):
    """What the real-capture experiments run."""
    # iterations of Algorithm 1 per agent (chosen on validation takes: docs/results/realmocap_length.md; paper: 50)
    epochs: int = 100
    preset: str = "end_chunks"  # config preset (docs/results/realmocap_ablation.md: the arm comes down in time)
    seeds: tuple[int, ...] = (0, 1, 2)  # training seeds; the first seed's agents give the full tables and the figure
    # exported pointing agent (.npz) for the guide clips (None: the installed agent when trained, else one trained
    # here on the sample library)
    point_agent: str | None = None
    import_workers: int = 1  # import the takes the cache lacks with N Blenders at once (Ray tasks)
    # join a Ray cluster: auto (started on this machine by ray start) or ray://HOST:PORT (None: a local Ray, no set-up)
    address: str | None = None

    def __post_init__(self) -> None:
        require_values(self, "seeds")


def run_experiments(settings: RealMocapSettings) -> dict:
    """All experiments of `settings` (RealMocapSettings); returns the realmocap results dict."""
    torch.set_num_threads(1)
    new_empty_scene()
    waves, byes, guides, env = _load_capture(settings)
    references = ClipReferences(env)
    seeds = list(dict.fromkeys(settings.seeds))
    results = {"source": "Bandai Namco Research motion dataset (CC BY-NC 4.0), read from ../shared/realmocap/",
               "command": _command(settings, seeds),
               "epochs": settings.epochs, "preset": settings.preset, "seeds": seeds,
               "labels": {"wave": label_table(waves), "bye": label_table(byes)},
               "tempos": tempo_table(waves, references)}

    experiments = {"wave": wave_split(waves), "holdout": style_holdout_split(waves)}
    results["label_reach"] = {name: label_reach(wave_rhythm.swinging(train_clips), wave_rhythm.swinging(test_clips))
                              for name, (train_clips, test_clips) in experiments.items()}
    evaluation_started = time.process_time()
    runs = {(name, seed): real_run(name, train_clips, test_clips, seed, settings)
            for name, (train_clips, test_clips) in experiments.items() for seed in seeds}
    reports = train_real_runs(runs.values(), settings.address, settings.workers)
    for name, (train_clips, test_clips) in experiments.items():
        trained = {seed: (runs[name, seed].settings.output, reports[runs[name, seed].settings.output])
                   for seed in seeds}
        sets = {"test": test_clips} if name == "holdout" else {"test": test_clips, "bye": byes}
        results[name], agent = _experiment(name, train_clips, sets, trained, env, references)
        if name == "wave":
            _frames_figure(agent, test_clips, env, Path(settings.results) / "realmocap_frames.png")
    results["evaluation_cpu_seconds"] = time.process_time() - evaluation_started
    results["guide"] = _guide(settings, seeds[0], guides, env)
    return results


def _load_capture(settings: RealMocapSettings) -> tuple[list, list, list, FKEnvironment]:
    """(waves, byes, guides, the FK environment): the capture's takes, imported where the cache lacks them."""
    root = require_realmocap(settings.realmocap)
    Path(settings.results).mkdir(parents=True, exist_ok=True)
    cache = Path(settings.runs) / "import_cache"
    if settings.address is not None:  # the import's Ray tasks, if any, and the training runs go to the cluster
        connect(settings.address)
    with blender_output():
        waves, byes, guides = (load_folder(f, root, cache, settings.import_workers) for f in ("wave", "bye", "guide"))
        env = FKEnvironment()
    return waves, byes, guides, env


def _command(settings: RealMocapSettings, seeds: list[int]) -> str:
    """The command that regenerates the results."""
    command = (f"nice -n 15 python -m trainer.scripts.realmocap --epochs {settings.epochs} --preset {settings.preset} "
               f"--seeds {' '.join(str(seed) for seed in seeds)}")
    if settings.point_agent:
        command += f" --point-agent {settings.point_agent}"
    return command


def _experiment(name: str, train_clips: list, sets: dict, trained: dict, env: FKEnvironment,
                references: ClipReferences) -> tuple[dict, baselines.AgentMethod]:
    """(the experiment's results entry, the first seed's agent): every method on every set and request, each
    seed's agent on them too. trained: {seed: (its run's output folder, its training report)}, first seed first."""
    agents = {seed: baselines.AgentMethod(Path(output) / "agent.npz") for seed, (output, _) in trained.items()}
    seeds = list(trained)
    report, agent = trained[seeds[0]][1], agents[seeds[0]]
    methods = {"rlanimate": agent, "nearest_clip": baselines.NearestClip(train_clips),
               "procedural_ik": ProceduralIK(baselines.mean_start_pose(train_clips))}
    entry = {"train_clips": len(train_clips), "episodes": report["episodes"],
             "train_seconds": report["train_seconds"],
             "seen": _summary(compare({"rlanimate": agent}, scoring.select_clips(
                 train_clips, (behaviours.WAVE,), scoring.SEEN_CLIP_COUNT), env, references)["rlanimate"]),
             "train_cpu_seconds": {str(seed): trained[seed][1]["train_cpu_seconds"] for seed in seeds}}
    if name == "holdout":
        entry["held_out_styles"] = list(HOLDOUT_STYLES)
    for (set_name, clips), (suffix, with_tempo) in itertools.product(sets.items(), REQUESTS.items()):
        key = set_name + suffix
        entry[key] = compare(methods, clips, env, references, with_tempo)
        entry[f"{key}_seeds"] = {str(seeds[0]): seed_summary(entry[key]["rlanimate"])}
        for seed in seeds[1:]:
            result = compare({"rlanimate": agents[seed]}, clips, env, references, with_tempo)["rlanimate"]
            entry[f"{key}_seeds"][str(seed)] = seed_summary(result)
    return entry, agent


def _frames_figure(agent: baselines.AgentMethod, test_clips: list, env: FKEnvironment, path: Path) -> None:
    """realmocap_frames.png: the agent's waves beside the test takes nearest exaggerations 0.1, 0.7 and 1."""
    chosen = [min(test_clips, key=lambda c: abs(c.exaggeration - e)) for e in (0.1, 0.7, 1.0)]
    generated = baselines.generate_for(agent, chosen)
    frames_figure(env, [(f"{c.style} {c.arm.lower()} {c.take}\ne = {c.exaggeration:.2f}", c.rotvecs, g)
                        for c, g in zip(chosen, generated, strict=True)], path)


def _guide(settings: RealMocapSettings, seed: int, guides: list, env: FKEnvironment) -> dict:
    """The guide experiment's results: each method's forearm angle on the guide takes, asked as pointing; or
    why it was skipped (no pointing agent and no sample library to train one on)."""
    try:
        point_method, point_clips = point_agent_and_library(settings.point_agent, settings.runs, settings.epochs, seed)
    except RLAnimateError as error:
        return {"skipped": str(error)}
    guide_methods = {"rlanimate": point_method, "nearest_clip": baselines.NearestClip(point_clips),
                     "procedural_ik": ProceduralIK(baselines.mean_start_pose(point_clips))}
    return {"point_agent": str(shown(point_method.path.resolve())),
            **{name: guide_angles(method, guides, env) for name, method in guide_methods.items()}}


def _method_rows(comparison):
    return {method: _summary(result) for method, result in comparison.items()}


def baseline_sets(results: dict) -> dict:
    """The real-data section of baselines.json: {set: {method: {score, smoothness, clips}}}."""
    sets = {"waves, takes 009-010 (28)": _method_rows(results["wave"]["test"]),
            "goodbye waves, dataset 1 (14)": _method_rows(results["wave"]["bye"]),
            f"waves, unseen styles {' + '.join(HOLDOUT_STYLES)} (40)": _method_rows(results["holdout"]["test"])}
    if "skipped" in results["guide"]:
        return sets
    sets["guide clips as pointing (14)"] = {
        method: {"forearm_angle_deg": entry["mean_forearm_angle_deg"]}
        for method, entry in results["guide"].items() if isinstance(entry, dict)}
    return sets


