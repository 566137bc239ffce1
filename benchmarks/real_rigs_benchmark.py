"""Generate Gesture on every rig in ../shared/rigs and on the Rigify rigs the tests build (FK, IK, with a game
export skeleton), measured on the bones the mesh deforms with, as Blender plays them (tests/addon/real_rigs.py).

Per rig: whether it is accepted (as it comes, with 'Generate, Muting Constraints', or with a user bone map),
Point's miss (degrees between the deformed index finger, base joint to tip joint, and the line from its base
to the target; median over the pointing hold) over random unseen targets, both arms alternating, with Exact
Aim on and off, a 150-frame wave's strokes, and the deformed wrist's least travel over those gestures in arm
lengths. Writes the "Real rigs" section of docs/BENCHMARKS.md.

Every rig is measured still (its animation taken off, bones at rest: a gesture starts from the standing pose),
as Generate finds a rig with no animation; the rigs whose files bring an animation of their own are measured
over it as well, in rows of their own ('over its ...').

Run: `nice -n 10 python benchmarks/real_rigs_benchmark.py [--targets 12] [--seed 5] [--rigs ROW ...] [--no-write]`;
--rigs measures only the rows named and rewrites only those rows of the section, noting when they were rerun.
"""
import argparse
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "tests", ROOT / "tests" / "addon"):
    sys.path.insert(0, str(path))

import bpy  # noqa: E402
from report import BENCHMARKS_MD, write_section  # noqa: E402  (benchmarks/report.py)

import addon_helpers as helpers  # noqa: E402
import real_rigs  # noqa: E402

#: (row, family, source) of every rig: a ../shared/rigs file (real_rigs.FILES) or a Rigify build, still; a
#: row '<file>_own' measures the file over its own animation (real_rigs.ACTIONS, else its active action).
RIGS = (
    ("ue_control_rig", "UE4 names, deform bones copy DRV_ twins", "Mesh2Motion (real file)"),
    ("ue_gltf", "UE4 names, glTF", "Mesh2Motion (real file)"),
    ("seed_san", "metarig names, A-pose, twist bone", "UniVRM (real file)"),
    ("kenney", "Mixamo-like, 3.7 units tall", "Mesh2Motion / Kenney (real file)"),
    ("quaternius", "outside the families (Palm, no Hand, one Fingers bone)", "Quaternius (real file)"),
    ("quaternius_own", "the same, over its own Female_Clapping (the file's active action)", "Quaternius (real file)"),
    ("quaternius_palm_only", "the same, mapped with no finger: points along its palm", "Quaternius (real file)"),
    ("gdbot", "outside the families (_FK/_IK chains, no collar, hips under torso)", "GDQuest (real file)"),
    ("gdbot_own", "the same, over its own Idle (its active action is a fall)", "GDQuest (real file)"),
    ("vrm0_robot", "VRM 0.x, from the file's own humanoid map", "UNAVI (real file)"),
    ("vrm1_robot", "VRM 1.0 rewritten from it, every joint renamed", "built from the real file"),
    ("rigify_fk", "Rigify, arms in FK", "built by Rigify (real tool)"),
    ("rigify_ik", "Rigify, arms in IK", "built by Rigify (real tool)"),
    ("rigify_export", "Rigify + game export skeleton", "built by Rigify (real tool)"),
    ("rigify_no_fingers", "Rigify without palms or fingers: points along its hand", "built by Rigify (real tool)"),
    ("godot_no_fingers", "Godot humanoid names, no fingers: points along its hand", "sample, renamed"),
)


def _file(row):
    """The real_rigs.FILES name a row reads (the VRM 1.0 one is rewritten from the VRM 0.x file), or None."""
    name = row.removesuffix("_own").removesuffix("_palm_only")
    return "vrm0_robot" if name == "vrm1_robot" else name if name in real_rigs.FILES else None


def _bone_map(row):
    """The real_rigs.USER_BONE_MAPS name a row is mapped with when refused as it comes, or None."""
    return row if row in real_rigs.USER_BONE_MAPS else _file(row) if _file(row) in real_rigs.USER_BONE_MAPS else None


def _load(name, folder):
    if name == "godot_no_fingers":
        return real_rigs.godot_without_fingers()
    if name.startswith("rigify_"):
        return real_rigs.rigify_rig("IK" if name == "rigify_ik" else "FK", export=name == "rigify_export",
                                    fingers=name != "rigify_no_fingers")
    if name == "vrm1_robot":
        return real_rigs.import_gltf(real_rigs.vrm1_file(folder), folder)
    return real_rigs.load_shared(_file(name), folder, still=not name.endswith("_own"))


def _accept(rig, settings, name, folder):
    """(how it is accepted, mute constraints?) or (the refusal's first words, None)."""
    for mute in (False, True):
        try:
            real_rigs.wave(rig, settings, "RIGHT", 5000, mute=mute)
            return ("yes" if not mute else "with Generate, Muting Constraints"), mute
        except RuntimeError as error:
            refusal = str(error).removeprefix("Error: ")
    if _bone_map(name) is not None:
        settings.bone_map_file = real_rigs.write_bone_map(_bone_map(name), folder)
        try:
            real_rigs.wave(rig, settings, "RIGHT", 5000)
            return "with a user bone map (without one, refused naming the fix)", False
        except RuntimeError as error:
            refusal = str(error).removeprefix("Error: ")
    return "refused: " + refusal[:150].replace("|", "/") + "...", None


def measure(name, targets, seed, folder):
    settings = helpers.enable_addon()
    folder = folder / name
    folder.mkdir()
    rig = _load(name, folder)
    accepted, mute = _accept(rig, settings, name, folder)
    if mute is None:
        helpers.disable_addon()
        return accepted, None
    rng = np.random.default_rng(seed)
    exact, own, travel = [], [], []
    for k in range(targets):
        arm = ("RIGHT", "LEFT")[k % 2]
        for aimed, misses in ((True, exact), (False, own)):
            target = real_rigs.world_target(rig, settings, arm, rng)
            result, miss, moved = real_rigs.point(rig, settings, arm, target, 1 + 150 * (2 * k + aimed),
                                                  exact=aimed, mute=mute)
            assert result == {"FINISHED"}, (name, result)
            misses.append(miss)
            travel.append(moved)
    _, strokes, moved = real_rigs.wave(rig, settings, "RIGHT", 150 * (2 * targets + 2), mute=mute)
    travel.append(moved)
    helpers.disable_addon()
    return accepted, (np.array(exact), np.array(own), strokes, min(travel))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=12)
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--rigs", nargs="+", choices=[row for row, _, _ in RIGS], metavar="ROW",
                        help="measure only these rows and rewrite only them in the section (default: every row)")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp())
    rows, started = {}, time.perf_counter()
    for name, family, source in RIGS:
        if args.rigs and name not in args.rigs:
            continue
        if _file(name) is not None and real_rigs.shared_file(_file(name)) is None:
            rows[name] = f"| {name} | {family} | {source} | absent (../shared/rigs) | | | | |"
            continue
        accepted, measured = measure(name, args.targets, args.seed, folder)
        if measured is None:
            rows[name] = f"| {name} | {family} | {source} | {accepted} | - | - | - | - |"
        else:
            exact, own, strokes, travel = measured
            rows[name] = (f"| {name} | {family} | {source} | {accepted} | {np.median(exact):.2f} / {exact.max():.2f} "
                          f"| {np.median(own):.1f} / {own.max():.1f} | {strokes} | {travel:.2f} |")
        print(rows[name], flush=True)
    seconds, date = time.perf_counter() - started, time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    text = _rerun(rows, seconds, date) if args.rigs else _section(rows, args, seconds, date)
    print(text)
    if not args.no_write:
        write_section("## Real rigs", text)


def _rerun(rows, seconds, date):
    """The section as it stands with the rows measured replaced (or added, in RIGS order) and a line saying
    which rows were rerun, when and how long they took."""
    old = re.search(r"^## Real rigs\n.*?(?=^## |\Z)", BENCHMARKS_MD.read_text(), re.S | re.M).group(0)
    lines = old.rstrip("\n").split("\n")
    table = {
        line.split("|")[1].strip(): line for line in lines if line.startswith("| ") and not line.startswith("| rig |")
    }
    table.update(rows)
    head = [line for line in lines if not line.startswith(("|---", "Rows rerun"))
            and (not line.startswith("| ") or line.startswith("| rig |"))]
    ruler = next(line for line in lines if line.startswith("|---"))
    order = [row for row, _, _ in RIGS if row in table]
    note = (f"Rows rerun {date} with `--rigs {' '.join(rows)}` ({seconds:.0f} s, Blender {bpy.app.version_string}); "
            "the other rows are from the run above.")
    header_at = next(k for k, line in enumerate(head) if line.startswith("| rig |"))
    return "\n".join(head[:header_at] + [note, ""] + [head[header_at], ruler] + [table[row] for row in order])


def _section(rows, args, seconds, date):
    return "\n".join([
        "## Real rigs",
        "",
        f"Generate Gesture on every rig in `../shared/rigs` (made by others, imported as they come) and on Rigify "
        f"rigs generated by the Rigify add-on (tests/addon/real_rigs.py), measured on the bones the mesh deforms "
        f"with, as Blender plays them: {args.targets} random unseen Point targets per rig and Exact Aim setting "
        f"(both arms alternating, 120 frames, seed {args.seed}), miss in degrees of the deformed index finger "
        "(base joint to tip joint) at the hold (median / worst over the targets), a 150-frame wave's strokes, "
        "and the deformed wrist's least travel over those gestures, in arm lengths. Each rig is measured still "
        "(its animation taken off, bones at rest: gestures start from the standing pose); the `_own` rows measure "
        "a file over the animation it brings. Bundled agent.",
        "",
        "Regenerate: `nice -n 10 python benchmarks/real_rigs_benchmark.py` (`--rigs ROW ...`: only those rows)",
        "",
        f"Blender {bpy.app.version_string}, {seconds:.0f} s. Date: {date}.",
        "",
        "| rig | family | source | accepted | exact aim: median / worst deg | own aim: median / worst deg "
        "| wave strokes | hand travel |",
        "|---|---|---|---|---:|---:|---:|---:|",
        *rows.values(),
    ])


if __name__ == "__main__":
    main()
