"""A harder test split than the library's held-out clips: requests outside the training ranges, at
0.5x-1.5x the reference's length. The references are made by the same generator as the library
(trainer/motion/synthesis) with style seeds no library clip uses.

Point: targets with one of azimuth, elevation or distance outside the library's ranges (library_plan:
azimuth -60 to 95 degrees, elevation -40 to 55, 1.5-4 m), the other two inside. Wave: the library
already spans the whole legal exaggeration range [0, 1] (the extension refuses values outside it), so
the harder waves are new styles (rhythm, cycle count, tempo) across [0, 1], at its ends included. Each
request asks for LENGTH_SCALES[k] x its reference's length, cycling; its reference is the synthesised
clip time-warped to that length, so a wave asked for in half the time is compared with the same wave
played twice as fast.
"""
import numpy as np

from rlanimate_addon.core import behaviours, skeleton, spaces
from trainer.evaluation.baselines import time_warp
from trainer.motion import library_plan
from trainer.motion.clip import MotionClip
from trainer.motion.synthesis import FPS, GestureSpec, synthesise

SEED = 4242
LENGTH_SCALES = (0.5, 0.75, 1.25, 1.5)
#: Outside the library's ranges: (low, high) bands just beyond each end.
AZIMUTH_OUTSIDE_DEG = ((-80.0, -62.0), (97.0, 110.0))
ELEVATION_OUTSIDE_DEG = ((-50.0, -42.0), (57.0, 68.0))
DISTANCE_OUTSIDE_M = ((1.0, 1.4), (4.2, 6.0))
POINTS_PER_ARM = 6
WAVES_PER_ARM = 4


def _inside(rng, degrees_range):
    return np.radians(rng.uniform(*degrees_range))


def _outside(rng, bands):
    return rng.uniform(*bands[rng.integers(len(bands))])


def outside_target(rng, arm, which):
    """(3,) a target with `which` ('azimuth', 'elevation' or 'distance') outside the library's range."""
    sign = 1.0 if arm == "LEFT" else -1.0
    shoulder = skeleton.shoulder_rest_position(arm)
    azimuth = np.radians(_outside(rng, AZIMUTH_OUTSIDE_DEG)) if which == "azimuth" else \
        _inside(rng, np.degrees(library_plan.AZIMUTH_RANGE))
    elevation = np.radians(_outside(rng, ELEVATION_OUTSIDE_DEG)) if which == "elevation" else \
        _inside(rng, (0.0, np.degrees(library_plan.ELEVATION_RANGE[1])) if which == "distance"
                else np.degrees(library_plan.ELEVATION_RANGE))  # far targets above the shoulder: the floor limits none
    distance = _outside(rng, DISTANCE_OUTSIDE_M) if which == "distance" else rng.uniform(*library_plan.DISTANCE_RANGE)
    direction = np.array([sign * np.sin(azimuth) * np.cos(elevation), -np.cos(azimuth) * np.cos(elevation),
                          np.sin(elevation)])
    if direction[2] < 0:  # above the floor, as the library keeps its targets
        distance = min(distance, (shoulder[2] - library_plan.LOWEST_TARGET) / -direction[2])
    return shoulder + distance * direction


def harder_clips(seed=SEED):
    """MotionClips (split 'harder') of the harder requests, both arms, deterministic in `seed`."""
    rng = np.random.default_rng(seed)
    specs = []
    for arm in skeleton.ARMS:
        for k in range(POINTS_PER_ARM):
            target = outside_target(rng, arm, ("azimuth", "elevation", "distance")[k % 3])
            specs.append(GestureSpec(behaviours.POINT, arm, target=tuple(float(v) for v in target),
                                     seed=int(rng.integers(2**31 - 1))))
        for exaggeration in np.linspace(0.0, 1.0, WAVES_PER_ARM):
            specs.append(GestureSpec(behaviours.WAVE, arm, exaggeration=float(exaggeration),
                                     seed=int(rng.integers(2**31 - 1))))
    clips = []
    for k, spec in enumerate(specs):
        rotvecs = synthesise(spec).action_rotvecs()
        scale = LENGTH_SCALES[k % len(LENGTH_SCALES)]
        clips.append(MotionClip(
            name=f"harder_{behaviours.key(spec.behaviour)}_{spec.arm.lower()}_{k:02d}_x{scale:g}", source="synthesised",
            fps=float(FPS), rotvecs=time_warp(rotvecs, max(2, int(round(scale * len(rotvecs))))),
            behaviour=spec.behaviour, arm=spec.arm,
            attributes=(spec.exaggeration if spec.target is None  # a target behaviour's clip has a target
                        else spaces.pointing_direction(spec.arm, spec.target)),
            target=spec.target, exaggeration=spec.exaggeration, split="harder"))
    return clips
