"""Behaviour metrics of a method on a set of requests: does it wave, point, raise and lower the arm
like the reference clip of the same request? (core/behaviour_metrics.py; definitions in docs/METRICS.md)

A method answers generate(behaviour, arm, attributes, frame_count) -> (F, 15, 3) local rotations (the
baselines' protocol, trainer/evaluation/baselines.py); an agent's generate also takes `seed`.
`describe` turns rotations (F, 15, 3) into descriptions (F, 42): the bpy FK environment's
(`env.evaluate(r).descriptions`) or `core.kinematics.describe`, which agree to 1e-5.

Per request, the method's answer at the clip's own length gives the paper's score and smoothness and
the behaviour measures (`behaviour_metrics.compare`); its answer at the class-average length gives the
score against the time-scaled reference and the DTW time-aligned score. POINT is measured with the
method's own aim, or after aim correction (`aim.aim_at`) with exact_aim.
"""
import numpy as np
from scipy.stats import spearmanr

from rlanimate_addon.core import aim, behaviours, metrics, skeleton, spaces
from rlanimate_addon.core import behaviour_metrics as bm
from trainer.motion import library_plan
from trainer.motion.synthesis import GUIDE, RAISE_HAND

#: Pointing targets as the sample library draws them (trainer/motion/library_plan.py): azimuth from
#: across the body to out to the arm's side, elevation from the horizontal, distance from the shoulder.
AZIMUTH_DEG = (-60.0, 95.0)
ELEVATION_DEG = (-40.0, 55.0)
DISTANCE_M = (1.5, 4.0)
LOWEST_TARGET_M = 0.05
#: Guiding targets as the sample library draws them: azimuth, elevation (degrees), distance (m).
GUIDE_AZIMUTH_DEG = tuple(np.degrees(library_plan.GUIDE_AZIMUTH_RANGE))
GUIDE_ELEVATION_DEG = tuple(np.degrees(library_plan.GUIDE_ELEVATION_RANGE))
GUIDE_DISTANCE_M = library_plan.GUIDE_DISTANCE_RANGE
#: A raised hand's height must rise with the exaggeration: Spearman's rank correlation above this.
RAISE_MIN_SPEARMAN = 0.8
#: Seed of the random unseen pointing targets (`random_target_sweeps`).
RANDOM_TARGET_SEED = 2024
EXAGGERATIONS = (0.0, 0.25, 0.5, 0.75, 1.0)


def class_lengths(training_clips):
    """{behaviour: mean frame count} of the training clips ('POINT', 'WAVE', ...)."""
    lengths = {}
    for clip in training_clips:
        lengths.setdefault(clip.behaviour, []).append(len(clip.rotvecs))
    return {b: int(round(np.mean(v))) for b, v in lengths.items()}


def clip_target(clip):
    """(3,) the target of a target behaviour's clip in the character frame (None for an intensity behaviour's,
    or a clip without one)."""
    target = getattr(clip, "target", None)
    return None if target is None else np.asarray(target, dtype=np.float64)


def _answer(method, behaviour, arm, attributes, frames, target, exact_aim, seed=None):
    """(F, 15, 3) the method's answer to the request, aimed at `target` when `exact_aim` (a pointing behaviour's)."""
    rotvecs = (method.generate(behaviour, arm, attributes, frames) if seed is None
               else method.generate(behaviour, arm, attributes, frames, seed=seed))
    if exact_aim:
        rotvecs = aim.aim_at(rotvecs, arm, target)
    return rotvecs


def request_rows(method, clips, references, describe, lengths, exact_aim=False, seed=None):
    """One row per clip: name, behaviour, arm, score, smoothness, score_class_length, aligned_score and
    every measure of `behaviour_metrics.compare`. references: .get(clip) -> (descriptions, positions);
    `seed`: the method's variation seed (None: its deterministic answer)."""
    rows = []
    for clip in clips:
        behaviour, arm, target = clip.behaviour, clip.arm, clip_target(clip)
        aimed = exact_aim and clip.declared.aims
        own = describe(_answer(method, behaviour, arm, clip.attributes, len(clip.rotvecs), target, aimed, seed))
        at_class = describe(_answer(method, behaviour, arm, clip.attributes, lengths[behaviour], target, aimed, seed))
        reference, reference_positions = references.get(clip)
        positions = spaces.description_joint_positions(own)
        class_positions = spaces.description_joint_positions(at_class)
        row = {"name": clip.name, "behaviour": behaviours.key(behaviour), "arm": arm.lower(),
               "score": metrics.score(positions, reference_positions),
               "smoothness": metrics.smoothness(positions),
               "score_class_length": bm.score_at_length(class_positions, reference_positions),
               "aligned_score": bm.aligned_score(class_positions, reference_positions)}
        row.update(bm.compare(own, reference, clip.declared, arm, target))
        rows.append(row)
    return rows


def seed_variation(method, clips, describe, seeds):
    """Per clip: the mean distance (m) between the outputs of `seeds` at the clip's length, and whether
    the deterministic answer (no seed) repeats exactly. -> [{name, behaviour, variation, deterministic}]"""
    rows = []
    for clip in clips:
        behaviour, arm, frames = clip.behaviour, clip.arm, len(clip.rotvecs)
        outputs = [spaces.description_joint_positions(describe(method.generate(behaviour, arm, clip.attributes,
                                                                               frames, seed=seed)))
                   for seed in seeds]
        first, again = (method.generate(behaviour, arm, clip.attributes, frames) for _ in range(2))
        rows.append({"name": clip.name, "behaviour": behaviours.key(behaviour), "variation": bm.variation(outputs),
                     "deterministic": bool(np.array_equal(first, again))})
    return rows


def random_targets(rng, arm, count, azimuths=AZIMUTH_DEG, elevations=ELEVATION_DEG, distances=DISTANCE_M):
    """(count, 3) targets in the character frame, drawn uniformly over azimuth, elevation (degrees) and
    distance (m) ranges from the arm's rest shoulder (the library's pointing ranges unless given), at least
    LOWEST_TARGET_M above the floor."""
    sign = 1.0 if arm == "LEFT" else -1.0
    shoulder = skeleton.shoulder_rest_position(arm)
    targets = []
    while len(targets) < count:
        azimuth, elevation = np.radians(rng.uniform(*azimuths)), np.radians(rng.uniform(*elevations))
        direction = np.array([sign * np.sin(azimuth) * np.cos(elevation), -np.cos(azimuth) * np.cos(elevation),
                              np.sin(elevation)])
        target = shoulder + rng.uniform(*distances) * direction
        if target[2] >= LOWEST_TARGET_M:
            targets.append(target)
    return np.array(targets)


def random_target_sweeps(method, frames, describe, count, exact_aim=False, seed=RANDOM_TARGET_SEED):
    """{'left', 'right': pointing_sweep} over `count` random unseen targets per arm at `frames`: the same
    targets for every method and call with the same generator seed (left arm first)."""
    rng = np.random.default_rng(seed)
    return {arm.lower(): pointing_sweep(method, arm, random_targets(rng, arm, count), frames, describe, exact_aim)
            for arm in ("LEFT", "RIGHT")}


def pointing_sweep(method, arm, targets, frames, describe, exact_aim=False):
    """Pointing angle (degrees, median over the hold) and hold (s) for each target (T, 3) at `frames`."""
    angles, holds = [], []
    for target in targets:
        direction = spaces.pointing_direction(arm, target)
        rotvecs = _answer(method, behaviours.POINT, arm, direction, frames, target, exact_aim)
        descriptions = describe(rotvecs)
        measures = bm.point_measures(spaces.description_joint_positions(descriptions),
                                     bm.finger_direction(descriptions, arm), arm, target)
        angles.append(measures["angle"])
        holds.append(measures["hold_s"])
    return {"angles": angles, "holds": holds, "median_angle": float(np.median(angles)),
            "max_angle": float(np.max(angles)), "median_hold_s": float(np.median(holds))}


def exaggeration_sweep(method, arm, frames, describe, exaggerations=EXAGGERATIONS):
    """Wave measures at each exaggeration, and whether the swing rises strictly with it."""
    measures = [bm.wave_measures(spaces.description_joint_positions(
        describe(method.generate(behaviours.WAVE, arm, e, frames))), arm) for e in exaggerations]
    swings = [m["swing"] for m in measures]
    return {"exaggerations": list(exaggerations), "swing": swings, "cycles": [m["cycles"] for m in measures],
            "frequency": [m["frequency"] for m in measures],
            "swing_rising": bool(np.all(np.diff(swings) > 0))}


def guide_sweeps(method, frames, describe, count, seed=RANDOM_TARGET_SEED):
    """{'left', 'right': measures} of "this way" towards `count` random unseen targets per arm over the
    library's guiding ranges, at `frames`: the accepted share and the heading error, palm-up angle, reach
    and hold (median; extremes of the first two) of `behaviour_metrics.guide_measures`."""
    rng = np.random.default_rng(seed)
    sweeps = {}
    for arm in ("LEFT", "RIGHT"):
        measures = []
        for target in random_targets(rng, arm, count, GUIDE_AZIMUTH_DEG, GUIDE_ELEVATION_DEG, GUIDE_DISTANCE_M):
            descriptions = describe(method.generate(GUIDE, arm, spaces.pointing_direction(arm, target), frames))
            measures.append(bm.guide_measures(spaces.description_joint_positions(descriptions),
                                              bm.finger_direction(descriptions, arm), bm.palm_normal(descriptions, arm),
                                              arm, target))
        values = {key: np.array([m[key] for m in measures]) for key in measures[0]}
        sweeps[arm.lower()] = {
            "accepted_share": float(np.mean([bm.guide_accepted(m) for m in measures])),
            "heading_error_median": float(np.median(values["heading_error"])),
            "heading_error_max": float(values["heading_error"].max()),
            "palm_up_median": float(np.median(values["palm_up"])), "palm_up_max": float(values["palm_up"].max()),
            "reach_median": float(np.median(values["reach"])), "hold_s_median": float(np.median(values["hold_s"]))}
    return sweeps


def raise_sweep(method, arm, frames, describe, exaggerations=EXAGGERATIONS):
    """Raise-hand measures at each exaggeration; whether the height rises with it (Spearman's rank
    correlation above RAISE_MIN_SPEARMAN, NaN for a method whose height never changes)."""
    measures = [bm.raise_measures(spaces.description_joint_positions(
        describe(method.generate(RAISE_HAND, arm, e, frames))), arm) for e in exaggerations]
    heights = [m["height"] for m in measures]
    correlation = float(spearmanr(exaggerations, heights).correlation) if np.ptp(heights) > 0 else float("nan")
    return {"exaggerations": list(exaggerations), "height": heights,
            "forearm_from_vertical": [m["forearm_from_vertical"] for m in measures],
            "hold_s": [m["hold_s"] for m in measures], "strokes": [m["strokes"] for m in measures],
            "spearman": correlation, "height_rising": bool(correlation > RAISE_MIN_SPEARMAN)}


def summarise(rows):
    """{behaviour: summary} of request rows: means of the scores present, medians (and extremes where a
    bound applies) of the behaviour measures (pointing ones when the rows have them)."""
    summary = {}
    for behaviour in sorted({r["behaviour"] for r in rows}):
        group = [r for r in rows if r["behaviour"] == behaviour]

        def values(key, group=group):
            return np.array([r[key] for r in group], dtype=np.float64)

        entry = {"requests": len(group)}
        for key in ("score", "score_class_length", "aligned_score", "smoothness"):
            if key in group[0]:
                entry[key] = float(values(key).mean())
        for key in ("elevation_first_error", "elevation_last_error"):
            entry[f"{key}_median"], entry[f"{key}_max"] = float(np.median(values(key))), float(values(key).max())
        if "wave_accepted" in group[0]:  # a wave's measures (behaviour_metrics.MEASURES)
            for key in ("swing_ratio", "frequency_ratio", "hand_height_ratio"):
                entry[f"{key}_median"] = float(np.nanmedian(values(key)))
            entry["swing_ratio_min"], entry["swing_ratio_max"] = (float(values("swing_ratio").min()),
                                                                  float(values("swing_ratio").max()))
            entry["cycles_min"], entry["cycles_median"] = (
                float(values("cycles").min()),
                float(np.median(values("cycles"))),
            )
            entry["accepted_share"] = float(values("wave_accepted").mean())
        elif "pointing_angle" in group[0]:
            entry["pointing_angle_median"] = float(np.median(values("pointing_angle")))
            entry["pointing_angle_max"] = float(values("pointing_angle").max())
            entry["hold_ratio_median"] = float(np.median(values("hold_ratio")))
        elif "guide_accepted" in group[0]:
            for key in ("heading_error", "palm_up"):
                entry[f"{key}_median"], entry[f"{key}_max"] = float(np.median(values(key))), float(values(key).max())
            entry["reach_median"] = float(np.median(values("reach")))
            entry["hold_ratio_median"] = float(np.nanmedian(values("hold_ratio")))
            entry["accepted_share"] = float(values("guide_accepted").mean())
        elif "hand_height_error" in group[0] or "aim_error" in group[0]:  # measured by its kind
            key = "hand_height_error" if "hand_height_error" in group[0] else "aim_error"
            entry[f"{key}_median"], entry[f"{key}_max"] = float(np.median(values(key))), float(values(key).max())
            entry["free_arm_rise_max"] = float(values("free_arm_rise").max())
        elif "raise_accepted" in group[0]:
            entry["height_error_median"] = float(np.median(values("height_error")))
            entry["height_error_max"] = float(values("height_error").max())
            entry["forearm_from_vertical_max"] = float(values("forearm_from_vertical").max())
            entry["hold_s_min"], entry["strokes_max"] = float(values("hold_s").min()), float(values("strokes").max())
            entry["accepted_share"] = float(values("raise_accepted").mean())
        summary[behaviour] = entry
    return summary
