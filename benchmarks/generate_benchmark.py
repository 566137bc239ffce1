"""Generate Gesture speed: 120 frames on the sample rig, bake included, against Blender's own playback.

Times `bpy.ops.rlanimate.generate_gesture()` (the whole operator: reading the rig and target, the
numpy agent, aim correction, retargeting, blending and the bulk F-curve writes), its numpy part
alone, and `scene.frame_set` on each of the same 120 frames of the baked gesture (the sample rig
with its skinned mesh), in interleaved rounds, and writes the section "Generate Gesture" of
docs/BENCHMARKS.md (replacing only that section, appending it when absent).

Run: `nice -n 10 python benchmarks/generate_benchmark.py [--repeats N] [--no-write]`
"""
import argparse
import os
import platform
import statistics
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402
import addon_utils  # noqa: E402  (Blender's module, importable once bpy is)
import numpy as np  # noqa: E402

from rlanimate_addon.blender import armature_io, preferences  # noqa: E402
from rlanimate_addon.core import gesture  # noqa: E402
from trainer.blender_io import rig_session  # noqa: E402
from trainer.paths import SAMPLE_RIG_BLEND  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)

FRAMES = 120
SECTION = "## Generate Gesture"


def fresh_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rlanimate_addon", default_set=True)
    rig = rig_session.load_rig(SAMPLE_RIG_BLEND, with_mesh=True)
    bpy.context.view_layer.objects.active = rig
    target = bpy.data.objects.new("Target", None)
    target.location = (-1.2, -2.5, 1.7)
    bpy.context.scene.collection.objects.link(target)
    settings = bpy.context.scene.rlanimate
    settings.target, settings.frame_count, settings.start_frame, settings.arm = target, FRAMES, 1, "RIGHT"
    return rig, settings


def clear_animation(rig):
    data = rig.animation_data
    for action in {data.action} | {s.action for t in data.nla_tracks for s in t.strips}:
        if action is not None:
            bpy.data.actions.remove(action)
    rig.animation_data_clear()


def time_generate(rig, behaviour):
    """Seconds for one Generate Gesture call on the unanimated rig."""
    bpy.context.scene.rlanimate.behaviour = behaviour
    start = time.perf_counter()
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    return time.perf_counter() - start


def numpy_part(rig):
    """A callable timing the bpy-free part alone: objectives, agent rollout, aim, retarget and blend."""
    agent = preferences.selected_agent(bpy.context)
    family, roles = armature_io.rig_roles_of(rig)
    rig_pose = armature_io.sample_rig(bpy.context, rig, roles, family, np.arange(1, FRAMES + 1))[0]
    request = gesture.GestureRequest("POINT", "RIGHT", FRAMES, targets=np.tile([-1.2, -2.5, 1.7], (FRAMES, 1)))

    def timed():
        start = time.perf_counter()
        gesture.gesture_rotations(agent, request, rig_pose)
        return time.perf_counter() - start
    return timed


def time_playback():
    """Seconds for scene.frame_set on each of the 120 baked frames (Blender's own evaluation)."""
    scene = bpy.context.scene
    start = time.perf_counter()
    for frame in range(1, FRAMES + 1):
        scene.frame_set(frame)
    return time.perf_counter() - start


def measure(rig, repeats):
    """{what: [seconds]} over `repeats` interleaved rounds, so that every measurement sees the
    machine in the same state; each round's playback evaluates the Point gesture it just baked."""
    time_generate(rig, "POINT")  # warm-up: loads the agent file
    clear_animation(rig)
    timed_numpy_part = numpy_part(rig)
    times = {"point": [], "playback": [], "wave": [], "numpy": []}
    for _ in range(repeats):
        times["point"].append(time_generate(rig, "POINT"))
        times["playback"].append(time_playback())
        clear_animation(rig)
        times["wave"].append(time_generate(rig, "WAVE"))
        clear_animation(rig)
        times["numpy"].append(timed_numpy_part())
    return times


def ms(values):
    return f"{1000 * min(values):.1f} | {1000 * statistics.median(values):.1f}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=25)
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})

    rig, _ = fresh_scene()
    times = measure(rig, args.repeats)
    point, wave, numpy_seconds, playback = times["point"], times["wave"], times["numpy"], times["playback"]
    paired = statistics.median(g / p for g, p in zip(point, playback))
    agent = preferences.selected_agent(bpy.context)
    trained = "untrained" if agent.metadata.get("training", {}).get("untrained") else "trained"

    text = f"""{SECTION}

Generate Gesture for {FRAMES} frames on the sample rig (armature and skinned mesh), bake included,
against Blender's own playback evaluation of the same {FRAMES} frames (`scene.frame_set` per frame).
Best and median of {args.repeats} interleaved rounds after a warm-up (Point, the playback of the gesture
it baked, Wave, the numpy part), in milliseconds, pinned to one CPU core (the machine is shared, so
the median carries other jobs' load; the best is the code's own cost); agent: the bundled default
({trained}). The ratio pairs each round's Point with its playback, so both see the machine alike.

Regenerate: `nice -n 10 python benchmarks/generate_benchmark.py`

Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs, Python {platform.python_version()},
bpy {bpy.app.version_string}, numpy {np.__version__}. Date: {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC.

| what | best ms | median ms |
|---|---:|---:|
| Generate Gesture, Point (operator, bake included) | {ms(point)} |
| Generate Gesture, Wave (operator, bake included) | {ms(wave)} |
| of which the numpy part (objectives, agent, aim, retarget, blend) | {ms(numpy_seconds)} |
| `scene.frame_set` x {FRAMES} (Blender's playback evaluation) | {ms(playback)} |

Generate / playback ratio (Point): median {paired:.2f} over the rounds, {min(point) / min(playback):.2f} best to best.
Budget: under 100 ms; aim: ratio below 1.
"""
    print(text)
    if not args.no_write:
        report.write_section(SECTION, text)


if __name__ == "__main__":
    main()
