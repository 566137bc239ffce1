"""The plan of the sample motion-clip library: which 200 clips, with which labels and split, from one seed.

Plain data; trainer/blender_io/clip_bake.py bakes and exports the planned clips
(`python -m trainer.scripts.clip_library`).

Plan, as in the paper: 50 point clips (25 per arm; targets 1.5-4 m away over the reachable front
hemisphere: across the body, ahead, out to the side, low to high) and 50 wave clips (25 per arm,
exaggeration spread over [0, 1]). 10 are held out for testing: 3 point clips per arm (targets inside
the training spread, never reused) and 2 wave clips per arm at exaggerations no training clip has.
Two more behaviours follow the same plan: 50 guide clips ("this way", targets like a point's over the
ground ahead and to the arm's side, GUIDE_* ranges) and 50 raise-hand clips (exaggerations like the
waves'), drawn from a generator of their own so the paper's 100 clips stay as they were.
"""
from dataclasses import dataclass

import numpy as np

from rlanimate_addon.core import skeleton, spaces
from trainer.motion.synthesis import FPS, GUIDE, RAISE_HAND, SYNTHESISERS, GestureSpec

DEFAULT_SEED = 2021
CLIPS_PER_ARM = 25
# Pointing targets: a 5 x 5 grid of (azimuth, elevation) cells from the pointing shoulder, one
# target jittered inside each cell. Azimuth 0 is straight ahead, positive out to the arm's side,
# negative across the body; elevation is from the horizontal.
AZIMUTH_RANGE = np.radians([-60.0, 95.0])
ELEVATION_RANGE = np.radians([-40.0, 55.0])
DISTANCE_RANGE = (1.5, 4.0)
LOWEST_TARGET = 0.05  # m above the floor
TEST_POINT_CELLS = ((1, 3), (2, 1), (3, 2))  # (azimuth band, elevation band): interior cells
TEST_WAVE_INDICES = (6, 18)
# Guiding targets: where a host shows the way, from a little across the body to out to the side, from
# the floor ahead to about shoulder height, 1.5-5 m away.
GUIDE_AZIMUTH_RANGE = np.radians([-30.0, 95.0])
GUIDE_ELEVATION_RANGE = np.radians([-35.0, 12.0])
GUIDE_DISTANCE_RANGE = (1.5, 5.0)


@dataclass(frozen=True)
class PlannedClip:
    file: str
    spec: GestureSpec
    split: str  # "train" or "test"


def _point_targets(arm, rng, azimuths=AZIMUTH_RANGE, elevations=ELEVATION_RANGE, distance_range=DISTANCE_RANGE):
    """25 targets (cell, xyz) for one arm, one per (azimuth, elevation) cell, in cell order."""
    sign = 1.0 if arm == "LEFT" else -1.0
    shoulder = skeleton.shoulder_rest_position(arm)
    az_edges = np.linspace(*azimuths, 6)
    el_edges = np.linspace(*elevations, 6)
    distances = rng.permutation(np.linspace(*distance_range, CLIPS_PER_ARM)) + rng.uniform(-0.04, 0.04, CLIPS_PER_ARM)
    targets = []
    for i in range(5):
        for j in range(5):
            az = rng.uniform(
                az_edges[i] + 0.15 * (az_edges[1] - az_edges[0]), az_edges[i + 1] - 0.15 * (az_edges[1] - az_edges[0])
            )
            el = rng.uniform(
                el_edges[j] + 0.15 * (el_edges[1] - el_edges[0]), el_edges[j + 1] - 0.15 * (el_edges[1] - el_edges[0])
            )
            direction = np.array([sign * np.sin(az) * np.cos(el), -np.cos(az) * np.cos(el), np.sin(el)])
            distance = float(np.clip(distances[5 * i + j], *distance_range))
            if direction[2] < 0:  # keep low targets above the floor
                distance = min(distance, (shoulder[2] - LOWEST_TARGET) / -direction[2])
            targets.append(((i, j), np.round(shoulder + distance * direction, 4)))
    return targets


def _wave_exaggerations(arm):
    """25 exaggerations for one arm; the two arms use interleaved grids, so no value repeats."""
    if arm == "LEFT":
        return np.round(np.linspace(0.0, 1.0, CLIPS_PER_ARM), 4)
    return np.round(np.linspace(0.02, 0.98, CLIPS_PER_ARM), 4)


def plan_library(seed=DEFAULT_SEED):
    """The 200 PlannedClips of the library, deterministic in `seed`: the paper's 100 point and wave clips,
    then 100 guide and raise-hand clips."""
    rng = np.random.default_rng(seed)
    style_seeds = iter(rng.integers(0, 2**31 - 1, size=4 * CLIPS_PER_ARM))
    plan = []
    for arm in skeleton.ARMS:
        for k, (cell, target) in enumerate(_point_targets(arm, rng)):
            split = "test" if cell in TEST_POINT_CELLS else "train"
            spec = GestureSpec("POINT", arm, target=tuple(float(v) for v in target), seed=int(next(style_seeds)))
            plan.append(PlannedClip(f"point_{arm.lower()}_{k:03d}.fbx", spec, split))
    for arm in skeleton.ARMS:
        for k, exaggeration in enumerate(_wave_exaggerations(arm)):
            split = "test" if k in TEST_WAVE_INDICES else "train"
            spec = GestureSpec("WAVE", arm, exaggeration=float(exaggeration), seed=int(next(style_seeds)))
            plan.append(PlannedClip(f"wave_{arm.lower()}_{k:03d}.fbx", spec, split))
    return plan + _more_behaviours(seed)


def _more_behaviours(seed):
    """The guide and raise-hand clips: planned as the point and wave clips are (a target grid with the same
    held-out cells; the waves' exaggeration grids and held-out indices), from their own generator."""
    rng = np.random.default_rng([seed, 1])
    style_seeds = iter(rng.integers(0, 2**31 - 1, size=4 * CLIPS_PER_ARM))
    plan = []
    for arm in skeleton.ARMS:
        targets = _point_targets(arm, rng, GUIDE_AZIMUTH_RANGE, GUIDE_ELEVATION_RANGE, GUIDE_DISTANCE_RANGE)
        for k, (cell, target) in enumerate(targets):
            split = "test" if cell in TEST_POINT_CELLS else "train"
            spec = GestureSpec(GUIDE, arm, target=tuple(float(v) for v in target), seed=int(next(style_seeds)))
            plan.append(PlannedClip(f"guide_{arm.lower()}_{k:03d}.fbx", spec, split))
    for arm in skeleton.ARMS:
        for k, exaggeration in enumerate(_wave_exaggerations(arm)):
            split = "test" if k in TEST_WAVE_INDICES else "train"
            spec = GestureSpec(RAISE_HAND, arm, exaggeration=float(exaggeration), seed=int(next(style_seeds)))
            plan.append(PlannedClip(f"raise_hand_{arm.lower()}_{k:03d}.fbx", spec, split))
    return plan


def manifest_entry(planned, frames):
    spec = planned.spec
    point = SYNTHESISERS[spec.behaviour][0] == "target"
    return {
        "file": planned.file, "behaviour": spec.behaviour, "arm": spec.arm,
        "target": list(spec.target) if point else None,
        "direction": [round(float(v), 6) for v in spaces.pointing_direction(spec.arm, spec.target)] if point else None,
        "exaggeration": None if point else spec.exaggeration,
        "frames": int(frames), "fps": FPS, "split": planned.split,
    }
