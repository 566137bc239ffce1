"""Where Generate Gesture's time goes: CPU time per stage of the operator, on the cases of
generate_benchmark.py (the sample rig at 24 fps, a Point: fresh at 120 frames, under an F-curve idle at
120 frames, fresh at 46 frames).

Each stage function is wrapped to add up the process's CPU time (time.process_time: Blender's own
threads included, and on a shared machine far steadier than wall time) over rounds after a warm-up;
the whole operator and `scene.frame_set` over the same frames (Blender's playback) are timed alike.
Stages: the checks (`generate._check`), reading the rig and the pose underneath
(`armature_io.sample_rig`), the policy rollout (`GestureAgent.rollout`), the rest of the numpy pipeline
(`gesture.gesture_rotations` less the rollout: retargeting, blending, aim, eyes), the keys per channel
(the rest of `generate._compute`: rotation modes, key reduction), the key writes (`generate._write`)
and the bake check (`bake_check.verify`, 3 frames played and measured); "other" is the operator less
them (undo and replace records, the frame put back). Writes the section "Generate Gesture, where the
time goes" of docs/BENCHMARKS.md.

With --functions it prints, instead, the CPU time per click spent in each of the pipeline's main
functions (FUNCTIONS; inclusive: a function's time holds the functions it calls) and in the bake
check's `scene.frame_set` calls (the first after the key writes, the others), and writes nothing.

Run: `nice -n 10 python benchmarks/generate_stages.py [--rounds N] [--root DIR] [--no-write] [--functions]`
(--root: time another checkout of the repository, e.g. an older commit exported with `git archive`).
"""
import argparse
import functools
import os
import platform
import statistics
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _root():
    """The checkout to time: --root's, else this one (read before anything imports the add-on)."""
    if "--root" in sys.argv:
        return Path(sys.argv[sys.argv.index("--root") + 1]).resolve()
    return HERE.parent


ROOT = _root()
sys.path[:0] = [str(ROOT / "benchmarks"), str(ROOT)]

import bpy  # noqa: E402
import generate_benchmark as cases  # noqa: E402  (the chosen checkout's benchmarks/generate_benchmark.py)
import numpy as np  # noqa: E402

from rlanimate_addon.blender import action_adapter, armature_io, bake_check, generate  # noqa: E402
from rlanimate_addon.core import aim, bake_measure, channels, gesture, runtime  # noqa: E402
from rlanimate_addon.core.rig import RigSkeleton  # noqa: E402

sys.path.insert(0, str(HERE))
import report  # noqa: E402  (this checkout's benchmarks/report.py)

SECTION = "## Generate Gesture, where the time goes"
#: (column, module, function) of each timed stage, outermost last.
STAGES = (("checks", generate, "_check"), ("rig read", armature_io, "sample_rig"),
          ("rollout", runtime.GestureAgent, "rollout"), ("numpy", gesture, "gesture_rotations"),
          ("compute", generate, "_compute"), ("key writes", generate, "_write"),
          ("bake check", bake_check, "verify"))

#: (module or class, function) timed by --functions, in pipeline order.
FUNCTIONS = ((runtime, "_gru_sequence"), (runtime.GestureAgent, "rollout"), (gesture, "played_finger_base"),
             (gesture, "fold_missing"), (gesture, "rest_swings"), (gesture, "retarget"), (gesture, "blend_from_pose"),
             (gesture, "aim_rig"), (gesture, "look_at"), (RigSkeleton, "pose_after"), (aim, "pointing_phase"),
             (channels, "rotation_keys"), (action_adapter, "write_keys"), (action_adapter.ActionTarget, "new_fcurve"),
             (bake_check, "verify"), (bake_measure, "planned_pose"), (bake_check, "deformed_bones"),
             (bake_check, "stand_in"))


def _timed(spent, label, function):
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        start = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            spent[label] += time.process_time() - start
    return wrapper


class _FrameTimedScene:
    """The scene the bake check is handed, its `frame_set` calls timed: the first after the key writes, and
    the others."""

    def __init__(self, scene, spent):
        self._scene, self._spent, self._label = scene, spent, "first frame_set"

    def frame_set(self, frame):
        start = time.process_time()
        self._scene.frame_set(frame)
        self._spent[self._label] += time.process_time() - start
        self._label = "other frame_set"

    def __getattr__(self, name):
        return getattr(self._scene, name)


def _time_check_frames(spent):
    """Time the bake check's frame_set calls into spent."""
    spent.update({"first frame_set": 0.0, "other frame_set": 0.0})
    verify = bake_check.verify
    bake_check.verify = functools.wraps(verify)(lambda scene, plan: verify(_FrameTimedScene(scene, spent), plan))


def measure(rounds, functions=False):
    """{case label: {stage: ms per click}} with the operator and playback, and the paired CPU ratio; with
    `functions`, {case label: {function: ms per click}} of FUNCTIONS and the bake check's frame_set calls,
    with the whole click."""
    stages = [(name, owner, name) for owner, name in FUNCTIONS if hasattr(owner, name)] if functions else STAGES
    spent = {label: 0.0 for label, _, _ in stages}
    for label, owner, name in stages:
        setattr(owner, name, _timed(spent, label, getattr(owner, name)))
    if functions:
        _time_check_frames(spent)
    rig, settings = cases.fresh_scene()
    idle = cases.key_idle(rig)
    idle.use_fake_user = True
    out = {}
    for label, animated, frames in cases.CASES:
        settings.frame_count = frames
        cases.remove_gesture(rig, idle if animated else None)
        cases.time_generate()  # warm-up
        for key in spent:
            spent[key] = 0.0
        clicks, plays = [], []
        for _ in range(rounds):
            cases.remove_gesture(rig, idle if animated else None)
            start = time.process_time()
            cases.time_generate()
            clicks.append(time.process_time() - start)
            start = time.process_time()
            cases.time_playback(frames)
            plays.append(time.process_time() - start)
        ms = {key: 1000.0 * value / rounds for key, value in spent.items()}
        if functions:
            out[label] = dict(ms, Generate=1000.0 * statistics.mean(clicks))
            continue
        row = {"checks": ms["checks"], "rig read": ms["rig read"], "rollout": ms["rollout"],
               "numpy rest": ms["numpy"] - ms["rollout"], "keys": ms["compute"] - ms["numpy"] - ms["rig read"],
               "key writes": ms["key writes"], "bake check": ms["bake check"]}
        row["Generate"] = 1000.0 * statistics.mean(clicks)
        row["other"] = row["Generate"] - sum(v for k, v in row.items() if k != "Generate")
        row["playback"] = 1000.0 * statistics.mean(plays)
        row["ratio"] = statistics.median(c / p for c, p in zip(clicks, plays, strict=True))
        out[label] = row
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--root", help="another checkout to time (its add-on and generate_benchmark.py)")
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    parser.add_argument("--functions", action="store_true", help="print CPU ms per click in FUNCTIONS instead")
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    if args.functions:
        rows = measure(args.rounds, functions=True)
        names = list(next(iter(rows.values())))
        print("| function | " + " | ".join(rows) + " |\n|---|" + "---:|" * len(rows))
        for name in names:
            print(f"| {name} | " + " | ".join(f"{row[name]:.2f}" for row in rows.values()) + " |")
        return
    load = os.getloadavg()[0]
    rows = measure(args.rounds)
    columns = ("checks", "rig read", "rollout", "numpy rest", "keys", "key writes", "bake check", "other",
               "Generate", "playback")
    table = "\n".join(f"| {label} | " + " | ".join(f"{row[c]:.1f}" for c in columns) + f" | **{row['ratio']:.2f}** |"
                      for label, row in rows.items())
    text = f"""{SECTION}

CPU milliseconds per click of Generate Gesture, by stage, on the cases of "Generate Gesture" above (the
sample rig at 24 fps, a Point), mean of {args.rounds} rounds after a warm-up, pinned to one CPU core, with
`scene.frame_set` over the same frames (playback) and the paired ratio of the two (median over rounds).
CPU time (`time.process_time`) rather than wall time: on a machine shared with other jobs it is the
steadier measure. The stages: the checks, reading the rig and the pose underneath, the policy rollout,
the rest of the numpy pipeline (retargeting, blending, aim, eyes), the keys per channel (rotation modes,
key reduction), the key writes, the bake check (3 frames played and measured), and the rest of the
operator (replace and undo records, the scene frame put back).

Regenerate: `nice -n 10 python benchmarks/generate_stages.py`

Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs (load average {load:.1f} at
start), Python {platform.python_version()}, bpy {bpy.app.version_string}, numpy {np.__version__}. Date:
{datetime.now(UTC):%Y-%m-%d %H:%M} UTC.

| case | checks | rig read | rollout | numpy rest | keys | key writes | bake check | other | Generate | playback | ratio |
|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|
{table}
"""
    print(text)
    if not args.no_write and ROOT == HERE.parent:  # another checkout's times are for comparing, not the docs
        report.write_section(SECTION, text)


if __name__ == "__main__":
    main()
