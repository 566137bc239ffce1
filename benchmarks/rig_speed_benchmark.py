"""Generate Gesture on the rigs animators use, against Blender's own playback of the frames it baked: paired
ratios in one process (issue 43).

Each case is built once in a fresh scene and saved; every round opens that file again (so each click finds
the rig as the animator left it), plays its first frame, times one click of Generate Gesture (the whole
operator: checks, the pose underneath, the agent, the keys, the bake check, the gestures baked again after
it), then `scene.frame_set` on each of the gesture's frames (Blender's evaluation of what it baked, meshes
deformed), and pairs the two. Clocks: wall time and the process's CPU time (`time.process_time`, Blender's
threads included). The process is pinned to one CPU core before Blender starts its threads.

Follow Target is timed on the sample character and the Rigify rig: a scripted drag of DRAG_MOVES target moves,
one every 1/60 s (an animator's drag, as the viewport sends it) or as soon as the previous move's handler returns,
counting the gesture's re-bakes per second; then the target rests and the gesture is baked in full.

Then it times the CPU milliseconds per click in Generate's stages (STAGES) for each case: where a click's time
goes (with --stages it prints those alone).

Run: `nice -n 10 python benchmarks/rig_speed_benchmark.py [--rounds N] [--cases NAME ...] [--no-write] [--stages]
[--root DIR]`
"""
import os

# Pinned before bpy starts its threads: every thread Blender starts then shares the one core.
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})

import argparse  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from datetime import UTC, datetime  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).resolve().parent
#: The checkout timed: --root's (an older commit exported with `git archive`, for a before / after), else this one.
ROOT = Path(sys.argv[sys.argv.index("--root") + 1]).resolve() if "--root" in sys.argv else HERE.parent
for _path in (HERE, ROOT / "tests" / "addon", ROOT):
    sys.path.insert(0, str(_path))

import bpy  # noqa: E402, I001  (before the test helpers: they import addon_utils, which needs bpy)
import numpy as np  # noqa: E402
from numpy.typing import ArrayLike  # noqa: E402

import addon_helpers as helpers  # noqa: E402
import real_rigs  # noqa: E402
import rig_variants  # noqa: E402
from report import write_section  # noqa: E402  (benchmarks/report.py)

SECTION = "## Generate on the rigs animators use"
#: The bones a Rigify animator keys in the benchmark's action, and the seed of the targets.
RIGIFY_KEYED = ("torso", "hips", "chest", "neck", "head", "upper_arm_fk.L", "forearm_fk.L", "shoulder.L")
SEED = 5


@dataclass(frozen=True)
class Case:
    name: str
    label: str
    build: Callable[[Path], bpy.types.Object]
    frames: int = 120
    mute: bool = False


def _settings(rig: bpy.types.Object, frames: int, start: int = 1, arm: str = "RIGHT") -> None:
    """Scene.rlanimate set for a Point of `frames` frames from `start` at a random unseen target (seeded)."""
    settings = bpy.context.scene.rlanimate
    target = real_rigs.world_target(rig, settings, arm, np.random.default_rng(SEED))
    settings.behaviour, settings.arm, settings.start_frame, settings.frame_count = "POINT", arm, start, frames
    settings.target = helpers.add_empty("Target", tuple(target))
    helpers.activate(rig)


def sample(frames: int) -> Callable[[Path], bpy.types.Object]:
    def build(folder: Path) -> bpy.types.Object:
        rig = helpers.load_sample_rig()
        _settings(rig, frames)
        return rig
    return build


def sample_over_clip(folder: Path) -> bpy.types.Object:
    """The sample character over a clip of its training set as its action: 26 bones keyed on every frame
    (location, rotation and scale), as a motion capture or a Mixamo animation comes."""
    rig = helpers.load_sample_rig()
    before = set(bpy.data.actions)
    bpy.ops.import_scene.fbx(filepath=str(ROOT / "sample_rigs" / "clips" / "raise_hand_left_003.fbx"))
    clip = next(a for a in bpy.data.actions if a not in before)
    for obj in [o for o in bpy.data.objects if o.name.startswith("RLAnimate_Character.")]:
        bpy.data.objects.remove(obj)
    data = rig.animation_data_create()
    data.action = clip
    if hasattr(data, "action_slot"):
        data.action_slot = clip.slots[0]
    _settings(rig, 120)
    return rig


def sample_composed(folder: Path) -> bpy.types.Object:
    """The sample character with a Point right on frames 1-120 (the first gesture, on a still rig); the
    click is a Wave left on 20-139 over it, after which the point is baked again (its aim is solved on the
    spine and head the wave turns)."""
    rig = helpers.load_sample_rig()
    _settings(rig, 120)
    assert bpy.ops.rlanimate.generate_gesture() == {"FINISHED"}
    settings = bpy.context.scene.rlanimate
    settings.behaviour, settings.arm, settings.start_frame, settings.exaggeration = "WAVE", "LEFT", 20, 0.7
    return rig


def shared(name: str) -> Callable[[Path], bpy.types.Object]:
    """A ../shared/rigs file brought in as a user does (real_rigs.load_shared), with its own animation."""
    def build(folder: Path) -> bpy.types.Object:
        rig = real_rigs.load_shared(name, folder)
        if name in real_rigs.USER_BONE_MAPS:
            bpy.context.scene.rlanimate.bone_map_file = real_rigs.write_bone_map(name, folder)
        _settings(rig, 120)
        return rig
    return build


def rigify(folder: Path) -> bpy.types.Object:
    """Rigify's generation of Blender's human metarig, face included, arms in FK, with a game export skeleton
    (real_rigs), a skinned mesh and an animator's action on its controls."""
    metarig = rig_variants._blender_metarig()
    bpy.ops.pose.rigify_generate()
    rig = bpy.context.active_object
    bpy.data.objects.remove(metarig)
    for side in ("L", "R"):
        rig.pose.bones["upper_arm_parent." + side]["IK_FK"] = 1.0
    deform = real_rigs._add_export_skeleton(rig, [b.name for b in rig.data.bones if b.use_deform])
    tube_mesh(rig, deform)
    key_controls(rig, RIGIFY_KEYED)
    _settings(rig, 120)
    return rig


def tube_mesh(rig: bpy.types.Object, bones: list[str], sides: int = 12, rings: int = 12) -> bpy.types.Object:
    """A mesh skinned to the named bones: a tube of `rings` x `sides` vertices along each, weighted to it."""
    vertices: list[tuple[float, ...]] = []
    faces: list[tuple[int, ...]] = []
    for name in bones:
        bone = rig.data.bones[name]
        head, tail = np.array(bone.head_local), np.array(bone.tail_local)
        x, z = np.array(bone.x_axis), np.array(bone.z_axis)
        angles = 2 * np.pi * np.arange(sides) / sides
        ring = 0.15 * bone.length * (np.cos(angles)[:, None] * x + np.sin(angles)[:, None] * z)  # (S, 3)
        first = len(vertices)
        for k in range(rings):
            vertices += [tuple(v) for v in head + (tail - head) * k / (rings - 1) + ring]
        faces += [(first + k * sides + j, first + k * sides + (j + 1) % sides,
                   first + (k + 1) * sides + (j + 1) % sides, first + (k + 1) * sides + j)
                  for k in range(rings - 1) for j in range(sides)]
    mesh = bpy.data.meshes.new("Body")
    mesh.from_pydata(vertices, [], faces)
    body = bpy.data.objects.new("Body", mesh)
    bpy.context.scene.collection.objects.link(body)
    body.parent = rig
    for k, name in enumerate(bones):
        body.vertex_groups.new(name=name).add(list(range(k * rings * sides, (k + 1) * rings * sides)), 1.0, "REPLACE")
    body.modifiers.new("Armature", "ARMATURE").object = rig
    return body


def key_controls(rig: bpy.types.Object, names: tuple[str, ...]) -> None:
    """An animator's sway on the named controls: a Bezier key every 10 frames over frames 1-150."""
    for k, name in enumerate(names):
        bone = rig.pose.bones[name]
        path = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}.get(
            bone.rotation_mode, "rotation_euler")
        for frame in range(1, 151, 10):
            angle = 0.08 * math.sin(0.1 * frame + k)
            if path == "rotation_quaternion":
                bone.rotation_quaternion = (math.cos(angle / 2), math.sin(angle / 2), 0.0, 0.0)
            elif path == "rotation_euler":
                bone.rotation_euler = (angle, 0.0, 0.0)
            bone.keyframe_insert(path, frame=frame)
    bpy.context.scene.frame_set(1)


CASES = (
    Case("sample_120", "sample character, at rest, 120 frames", sample(120)),
    Case("sample_46", "sample character, at rest, 46 frames", sample(46), frames=46),
    Case("sample_clip", "sample character over a clip (Mixamo names, 26 bones keyed every frame)",
         sample_over_clip),
    Case("sample_composed", "sample character: Wave left over a Point right, the point baked again",
         sample_composed),
    Case("ue_control_rig", "UE control rig (Mesh2Motion .blend), Muting Constraints", shared("ue_control_rig"),
         mute=True),
    Case("ue_gltf", "UE4-named glTF (Mesh2Motion)", shared("ue_gltf")),
    Case("seed_san", "Seed-san (metarig names, FBX)", shared("seed_san")),
    Case("kenney", "Kenney (Mixamo-like glTF)", shared("kenney")),
    Case("quaternius", "Quaternius over its own Female_Clapping (bone map)", shared("quaternius")),
    Case("gdbot", "GDQuest robot over its own Idle (bone map)", shared("gdbot")),
    Case("vrm0_robot", "VRM 0.x robot", shared("vrm0_robot")),
    Case("rigify", "Rigify (face, export skeleton, mesh, an action on its controls)", rigify),
)


def save(case: Case, folder: Path) -> tuple[Path, str, int, int]:
    """Build the case in a fresh scene and save it; returns (file, armature name, bones, mesh vertices)."""
    helpers.enable_addon()
    rig = case.build(folder)
    path = folder / f"{case.name}.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    vertices = sum(len(o.data.vertices) for o in bpy.data.objects if o.type == "MESH"
                   and any(m.type == "ARMATURE" and m.object == rig for m in o.modifiers))
    return path, rig.name, len(rig.data.bones), vertices


def _clock() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


def _since(start: tuple[float, float]) -> tuple[float, float]:
    wall, cpu = _clock()
    return wall - start[0], cpu - start[1]


def _open(path: Path, rig_name: str) -> bpy.types.Object:
    """The case's file opened again, its armature active and alone selected, its first frame played."""
    bpy.ops.wm.open_mainfile(filepath=str(path))
    rig = bpy.data.objects[rig_name]
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj is rig)
    bpy.context.view_layer.objects.active = rig
    bpy.context.scene.frame_set(int(bpy.context.scene.rlanimate.start_frame))
    return rig


def one_round(case: Case, path: Path, rig_name: str) -> tuple[tuple[float, float], tuple[float, float]]:
    """((wall, CPU) seconds of one click of Generate, (wall, CPU) of playing its frames) on the case's file."""
    _open(path, rig_name)
    scene, settings = bpy.context.scene, bpy.context.scene.rlanimate
    started = _clock()
    assert bpy.ops.rlanimate.generate_gesture(mute_constraints=case.mute) == {"FINISHED"}
    generate = _since(started)
    started = _clock()
    for frame in range(int(settings.start_frame), int(settings.start_frame) + case.frames):
        scene.frame_set(frame)
    return generate, _since(started)


def measure(case: Case, rounds: int, folder: Path) -> dict:
    path, rig_name, bones, vertices = save(case, folder)
    return {"case": case, "bones": bones, "vertices": vertices, **paired_rounds(case, rounds, path, rig_name),
            "path": path, "rig": rig_name, "without_agent": without_agent(case, rounds, path, rig_name)}


def paired_rounds(case: Case, rounds: int, path: Path, rig_name: str) -> dict[str, list[tuple[float, float]]]:
    """{"generate": [(wall, CPU) seconds], "playback": [...]} of `rounds` rounds after a warm-up round."""
    times = [one_round(case, path, rig_name) for _ in range(rounds + 1)][1:]
    return {"generate": [generate for generate, _ in times], "playback": [playback for _, playback in times]}


def without_agent(case: Case, rounds: int, path: Path, rig_name: str) -> dict[str, list[tuple[float, float]]]:
    """paired_rounds with the agent's rollout answered from its first answer to the same request (an agent that costs
    nothing; the warm-up round gives the answers): the floor the rest of Generate sets."""
    from rlanimate_addon.core import runtime

    rollout = runtime.GestureAgent.rollout
    answers: dict = {}

    def answered(agent: runtime.GestureAgent, objectives: ArrayLike, seed: int | None = None) -> np.ndarray:
        key = (np.asarray(objectives).tobytes(), seed)
        if key not in answers:
            answers[key] = rollout(agent, objectives, seed)
        return answers[key].copy()
    runtime.GestureAgent.rollout = answered  # type: ignore[method-assign, assignment]
    try:
        return paired_rounds(case, rounds, path, rig_name)
    finally:
        runtime.GestureAgent.rollout = rollout  # type: ignore[method-assign]


def _median(values: list[tuple[float, float]], clock: int) -> float:
    return statistics.median(v[clock] for v in values)


def _ratio(row: dict, clock: int) -> float:
    return statistics.median(g[clock] / p[clock] for g, p in zip(row["generate"], row["playback"], strict=True))


def table(rows: list[dict]) -> str:
    lines = ["| rig | bones | mesh vertices | frames | Generate wall ms | CPU ms | playback wall ms | CPU ms | "
             "ratio, wall | ratio, CPU | ratio, CPU, the agent at no cost |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in rows:
        lines.append(
            f"| {row['case'].label} | {row['bones']} | {row['vertices']:,} | {row['case'].frames} | "
            f"{1000 * _median(row['generate'], 0):,.0f} | {1000 * _median(row['generate'], 1):,.0f} | "
            f"{1000 * _median(row['playback'], 0):,.0f} | {1000 * _median(row['playback'], 1):,.0f} | "
            f"**{_ratio(row, 0):.2f}** | **{_ratio(row, 1):.2f}** | {_ratio(row['without_agent'], 1):.2f} |")
    return "\n".join(lines)


def missed(rows: list[dict]) -> str:
    """A sentence naming the cases at 120 frames over their target (CPU ratio), each with its ratio with the agent at
    no cost."""
    over = [f"{row['case'].label} {_ratio(row, 1):.2f} ({_ratio(row['without_agent'], 1):.2f})" for row in rows
            if row["case"].frames == 120 and _ratio(row, 1) > (0.75 if row["case"].name == "sample_120" else 1.0)]
    if not over:
        return "All are met."
    return ("Over their target (CPU ratio, and with the agent at no cost): " + "; ".join(over) + ".")


#: Target moves of a scripted drag, the seconds between two (the viewport's rate), and how far it goes (metres).
DRAG_MOVES, DRAG_EVERY, DRAG_LENGTH = 30, 1.0 / 60.0, 0.6


def drag(row: dict) -> dict:
    """Follow Target during a scripted drag on a case's file: its gesture's re-bakes per second (wall), the
    handler's median milliseconds per re-bake, and the milliseconds of the full bake once the target rests."""
    from rlanimate_addon.blender import follow_target, generate

    rig = _open(row["path"], row["rig"])
    settings = bpy.context.scene.rlanimate
    settings.follow_target = True
    assert bpy.ops.rlanimate.generate_gesture(mute_constraints=row["case"].mute) == {"FINISHED"}
    bake, baked = generate.bake, []

    def counted(*args: object, **kwargs: object) -> object:
        started = time.perf_counter()
        try:
            return bake(*args, **kwargs)
        finally:
            baked.append((time.perf_counter() - started, kwargs.get("preview", "")))
    generate.bake = counted
    try:
        start, step = np.array(settings.target.location), np.array([DRAG_LENGTH / DRAG_MOVES, 0.0, 0.0])
        time.sleep(follow_target.THROTTLE)
        began = time.perf_counter()
        for k in range(DRAG_MOVES):
            time.sleep(max(0.0, began + k * DRAG_EVERY - time.perf_counter()))
            settings.target.location = start + (k + 1) * step
            bpy.context.view_layer.update()  # the depsgraph handler bakes again, or waits
        seconds, during = time.perf_counter() - began, list(baked)
        started = time.perf_counter()
        settled: list = follow_target.settle()  # the target rests
        resting = time.perf_counter() - started
    finally:
        generate.bake = bake
    assert settled == [rig] and follow_target.note(rig) == "", follow_target.note(rig)
    kinds = [kind for _, kind in during]
    return {"case": row["case"], "rebakes": len(during), "seconds": seconds, "settle": resting,
            "each": {kind: statistics.median(t for t, k in during if k == kind) for kind in set(kinds)},
            "kinds": {kind: kinds.count(kind) for kind in set(kinds)}}


#: How each kind of preview reads in the report.
_KINDS = {"gesture": "the gesture", "aim": "the aim alone"}


def drag_table(drags: list[dict]) -> str:
    lines = ["| rig | moves | re-bakes during the drag: the gesture / the aim alone | re-bakes per second | "
             "ms per re-bake (median): the gesture / the aim alone | full bake once the target rests, ms |",
             "|---|---:|---:|---:|---:|---:|"]
    for d in drags:
        counts = " / ".join(str(d["kinds"].get(kind, 0)) for kind in _KINDS)
        each = " / ".join(f"{1000 * d['each'][kind]:.0f}" if kind in d["each"] else "-" for kind in _KINDS)
        lines.append(f"| {d['case'].label} | {DRAG_MOVES} | {counts} | **{d['rebakes'] / d['seconds']:.1f}** | "
                     f"{each} | {1000 * d['settle']:.0f} |")
    return "\n".join(lines)


#: (stage, module name, function) timed by --stages, inclusive; a stage inside the dependants' bakes counts to them.
STAGES = (("plan and checks", "generate", "_plan"), ("rig read", "armature_io", "sample_rig"),
          ("agent and aim", "generate", "_rotations"), ("key writes", "generate", "_write"),
          ("bake check", "bake_check", "verify"), ("dependants", "generate", "_cascade"))


def stages(row: dict, rounds: int) -> dict[str, float]:
    """{stage: CPU ms per click} of a case (STAGES, and the click), over `rounds` clicks after the first."""
    from rlanimate_addon.blender import armature_io, bake_check, generate

    modules = {"generate": generate, "armature_io": armature_io, "bake_check": bake_check}
    spent = dict.fromkeys([label for label, _, _ in STAGES] + ["Generate"], 0.0)
    inside: list[str] = []

    def timed(label: str, function: Callable) -> Callable:
        def wrapper(*args: object, **kwargs: object) -> object:
            counted = "dependants" not in inside
            inside.append(label)
            started = time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                inside.pop()
                spent[label] += (time.process_time() - started) if counted else 0.0
        return wrapper
    originals = [(modules[module], name, getattr(modules[module], name)) for _, module, name in STAGES]
    for (label, _, _), (module, name, function) in zip(STAGES, originals, strict=True):
        setattr(module, name, timed(label, function))
    try:
        for k in range(rounds + 1):
            if k == 1:
                spent = dict.fromkeys(spent, 0.0)
            spent["Generate"] += one_round(row["case"], row["path"], row["rig"])[0][1]
    finally:
        for module, name, function in originals:
            setattr(module, name, function)
    return {label: 1000.0 * value / rounds for label, value in spent.items()}


def stages_table(rows: list[dict], rounds: int) -> str:
    timed = [(row["case"].label, stages(row, rounds)) for row in rows]
    header = [label for label, _, _ in STAGES] + ["other", "Generate"]
    lines = ["| rig | " + " | ".join(header) + " |", "|---|" + "---:|" * len(header)]
    for label, ms in timed:
        other = ms["Generate"] - sum(ms[stage] for stage, _, _ in STAGES)
        values = [ms[stage] for stage, _, _ in STAGES] + [other, ms["Generate"]]
        lines.append(f"| {label} | " + " | ".join(f"{value:.1f}" for value in values) + " |")
    return "\n".join(lines)


def section(rows: list[dict], drags: list[dict], profile: str, args: argparse.Namespace, load: float,
            seconds: float) -> str:
    from rlanimate_addon.blender import follow_target

    follow_target_keep_up = follow_target.KEEP_UP
    return f"""{SECTION}

Generate Gesture (Point, right arm, a seeded unseen target, the whole operator) against Blender's own playback
of the frames it baked (`scene.frame_set` on each, meshes deformed), paired round by round in one process, on
the rigs of `../shared/rigs` as they import (their own animation, a user bone map where one is needed), the
sample character at rest at 120 and 46 frames and over a clip of its training set as its action, a gesture
composed over another (a Wave left on frames 20-139 over a Point right on 1-120: the point is baked again after
it, as its aim is solved on the spine and head the wave turns), and a Rigify rig generated in the benchmark
(Blender's human metarig, face included, by Rigify's own generate; a game export skeleton of Copy Transforms
bones; a mesh of a 12 x 12 tube per export bone, about Seed-san's size; an animator's sway keyed on
{len(RIGIFY_KEYED)} controls). Each round opens the case's file again; median of {args.rounds} rounds after a
warm-up, wall and CPU (`time.process_time`, Blender's threads included), the process and every thread Blender
starts pinned to one core; the ratio is the median of the rounds' paired ratios. The last column pairs the
same rounds again with the agent's rollout answered from its first answer to the same request, as if the agent
cost nothing: the floor the rest of Generate (the rig read, Exact Aim, the keys, the bake check) sets.

Regenerate: `nice -n 10 python benchmarks/rig_speed_benchmark.py`

Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other engineers' jobs (load average
{load:.1f} at start), Python {platform.python_version()}, bpy {bpy.app.version_string}, numpy {np.__version__};
{seconds:.0f} s. Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.

{table(rows)}

Targets: at most 1.0 on every rig at 120 frames, 0.75 on the sample character at rest, the Rigify
rig under 1 s a click. {missed(rows)}

Follow Target, on the same files: Generate with Follow Target on, then a scripted drag of {DRAG_MOVES} target
moves {100 * DRAG_LENGTH / DRAG_MOVES:.0f} cm apart, one every {1000 * DRAG_EVERY:.1f} ms or as soon as the
handler of the move before returns; re-bakes per second over the drag (wall). While the target is dragged each
re-bake is a preview (blender/follow_target.py): "the gesture", the agent, the aim, the keys and the bake check
for the new position over the pose underneath as the drag's first re-bake read it (no frame played again),
without the gestures that depend on it; where that takes longer than 1/{follow_target_keep_up:g} s, "the aim alone"
for the rest of the drag, Exact Aim and the eyes solved for the new position over the gesture baked last, its
bake checked. Once the target rests, the gesture is baked in full as Generate bakes it (the agent run, the rig
read again, its dependants baked again), and its keys are Generate's for that position, bit for bit
(`tests/addon/test_follow_target.py`).

{drag_table(drags)}

Targets: at least 20 re-bakes a second on the sample character, 5 on the Rigify rig.

Where a click's time goes: CPU milliseconds per click in Generate's stages, on the same files (the mean of
{args.rounds} clicks after a warm-up, the instrumented functions' inclusive time; "dependants" is the gestures
baked again after the click's own, stages inside it counted to it; "other" is the rest of the operator: the
checks before the plan, undo, the gesture list, the scene evaluated again once, the meshes deformed).
"rig read" is the pose underneath and the rig's rest (numpy where `blender/pose_underneath.py` can, else
Blender playing the frames, the armature alone); "agent and aim" runs the agent and Exact Aim in numpy; "bake
check" plays the gesture's frames through Blender.

{profile}
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--cases", nargs="*", default=[c.name for c in CASES])
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    parser.add_argument("--stages", action="store_true", help="print CPU ms per stage instead")
    parser.add_argument("--root", help="time another checkout of the repository")
    args = parser.parse_args()
    load, started = os.getloadavg()[0], time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        rows = [measure(case, args.rounds, Path(folder)) for case in CASES if case.name in args.cases]
        if args.stages:
            print(stages_table(rows, args.rounds))
            return
        drags = [drag(row) for row in rows if row["case"].name in DRAGGED]
        profile = stages_table(rows, args.rounds)
    text = section(rows, drags, profile, args, load, time.perf_counter() - started)
    print(text)
    if not args.no_write and not args.root:
        write_section(SECTION, text)


#: The cases Follow Target is timed on.
DRAGGED = ("sample_120", "rigify")


if __name__ == "__main__":
    main()
