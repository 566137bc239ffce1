"""Behaviours as data changes nothing for point and wave: this tree against a base revision, bit for bit.

    python benchmarks/behaviour_identity_check.py [--base eaed0e4] [--epochs 3]

The base revision is extracted (git archive) into a temporary folder; each check runs in both trees in a
fresh process and compares what they wrote:
  core     the shipped agent through core.gesture (two points, two waves, seeded and not): every array;
  blender  Generate Gesture on the sample character (Point with and without Exact Aim, a seeded Wave):
           every key of every curve written;
  composed gestures over one another on the sample character (a Point right, a seeded Wave left over
           it, the point baked again, then the point generated again at another target): every key of
           every curve written; the pose underneath each is the others' layers;
  trainer  a debug-preset training run (point and wave, seed 2): every weight array of agent.npz and
           every number of metrics.jsonl but the timings.
The clip import cache of this tree is copied into the base tree, so both read the same imported clips.
"""
import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CACHE = Path("sample_rigs") / "clips" / ".import_cache"


def core(root, out):
    from rlanimate_addon.core import gesture, runtime
    agent = runtime.load_agent(root / "rlanimate_addon" / "agents" / "default.npz")
    arrays = {}
    for k, (behaviour, arm, seed, frames) in enumerate([("POINT", "RIGHT", None, 90), ("POINT", "LEFT", 3, 60),
                                                        ("WAVE", "RIGHT", None, 120), ("WAVE", "LEFT", 5, 70)]):
        targets = np.tile([1.5 if arm == "LEFT" else -1.5, -2.0, 1.6], (frames, 1)) if behaviour == "POINT" else None
        request = gesture.GestureRequest(behaviour, arm, frames, targets=targets, exaggeration=0.7, seed=seed)
        bones, keyed, under = gesture.gesture_rotations(agent, request, gesture.canonical_rig())
        arrays.update({f"{k}_bones": np.array(bones), f"{k}_keyed": keyed, f"{k}_under": under})
    np.savez(out, **arrays)


def blender(root, out):
    sys.path.insert(0, str(root / "tests" / "addon"))
    import bpy  # noqa: F401, I001  (before the helpers: a base tree's may import addon_utils first, which needs bpy)
    import addon_helpers
    settings = addon_helpers.enable_addon()
    rig = addon_helpers.load_sample_rig()
    target = addon_helpers.add_empty("Target", (-1.2, -2.5, 1.7))
    for values in (dict(behaviour="POINT", arm="RIGHT", target=target, start_frame=1, frame_count=100),
                   dict(behaviour="WAVE", arm="LEFT", exaggeration=0.7, start_frame=150, frame_count=120, seed=3),
                   dict(behaviour="POINT", arm="LEFT", target=target, exact_aim=False, start_frame=300,
                        frame_count=60)):
        assert addon_helpers.generate(rig, settings, **values) == {"FINISHED"}
    np.savez(out, **_keys(rig))


def composed(root, out):
    sys.path.insert(0, str(root / "tests" / "addon"))
    import bpy  # noqa: F401, I001  (before the helpers, as in `blender`)
    import addon_helpers
    settings = addon_helpers.enable_addon()
    rig = addon_helpers.load_sample_rig()
    first = addon_helpers.add_empty("Target", (-1.2, -2.5, 1.7))
    second = addon_helpers.add_empty("Other", (1.3, -2.2, 1.5))
    for values in (dict(behaviour="POINT", arm="RIGHT", target=first, start_frame=1, frame_count=120),
                   dict(behaviour="WAVE", arm="LEFT", exaggeration=0.7, start_frame=20, frame_count=120, seed=3),
                   dict(behaviour="POINT", arm="RIGHT", target=second, start_frame=1, frame_count=120)):
        assert addon_helpers.generate(rig, settings, **values) == {"FINISHED"}
    np.savez(out, **_keys(rig))


def _keys(rig):
    """{action|data path|index: (2K,) the keys' frames and values} of every curve of the rig's gestures."""
    from rlanimate_addon.blender import action_adapter, gestures
    keys = {}
    for placed in gestures.placed_gestures(rig):
        # Every action of the gesture: its main and torso layers (a tree from before issue 42 has the one).
        for action in [layer.action for layer in getattr(placed, "layers", {}).values()] or [placed.action]:
            for curve in action_adapter.all_fcurves(action):
                co = np.zeros(2 * len(curve.keyframe_points))
                curve.keyframe_points.foreach_get("co", co)
                keys[f"{action.name}|{curve.data_path}|{curve.array_index}"] = co
    return keys


def trainer(root, out, epochs):
    subprocess.run([sys.executable, "-m", "trainer.scripts.train", "--preset", "debug", "--epochs", str(epochs),
                    "--behaviour", "both", "--seed", "2", "--eval-every", "0", "--quiet", "--output", str(out)],
                   cwd=root, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _child(kind, root, out, epochs):
    sys.path.insert(0, str(root))
    {"core": lambda: core(root, out), "blender": lambda: blender(root, out), "composed": lambda: composed(root, out),
     "trainer": lambda: trainer(root, out, epochs)}[kind]()


def _same_npz(a, b):
    with np.load(a) as x, np.load(b) as y:
        return sorted(x.files) == sorted(y.files) and all(np.array_equal(x[k], y[k]) for k in x.files), len(x.files)


def _difference(a, b):
    """How two npz files differ: the arrays of the same name and shape that differ, and by how much at most."""
    with np.load(a) as x, np.load(b) as y:
        pairs = [(x[k], y[k]) for k in set(x.files) & set(y.files) if x[k].shape == y[k].shape]
        gaps = [float(np.abs(u - v).max()) for u, v in pairs if u.size and not np.array_equal(u, v)]
    return f"{len(gaps)} differ, by at most {max(gaps, default=0.0):.2g}"


def _same_run(a, b):
    """Whether two runs trained the same weights and logged the same numbers; and how many weight arrays."""
    with np.load(a / "agent.npz") as x, np.load(b / "agent.npz") as y:
        names = [k for k in x.files if k != "__metadata__"]  # the metadata differs: format, commit, date
        weights = sorted(x.files) == sorted(y.files) and all(np.array_equal(x[k], y[k]) for k in names)

    def numbers(run):
        return [{k: v for k, v in json.loads(line).items() if "seconds" not in k}
                for line in (run / "metrics.jsonl").read_text().splitlines()]

    return weights and numbers(a) == numbers(b), len(names)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default="eaed0e4")
    parser.add_argument("--epochs", type=int, default=3)
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        kind, root, out = args.child
        return _child(kind, Path(root), Path(out), args.epochs)
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        base = folder / "base"
        base.mkdir()
        archive = subprocess.run(["git", "archive", args.base], cwd=ROOT, check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(base)], input=archive, check=True)
        if (ROOT / CACHE).is_dir():
            shutil.copytree(ROOT / CACHE, base / CACHE)
        for kind in ("core", "blender", "composed", "trainer"):
            outs = []
            for name, root in (("base", base), ("this", ROOT)):
                out = folder / f"{kind}_{name}" if kind == "trainer" else folder / f"{kind}_{name}.npz"
                subprocess.run([sys.executable, __file__, "--epochs", str(args.epochs), "--child", kind, str(root),
                                str(out)], cwd=folder, check=True, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
                outs.append(out)
            same, count = (_same_run if kind == "trainer" else _same_npz)(*outs)
            how = "identical" if same else "DIFFERENT" + ("" if kind == "trainer" else f" ({_difference(*outs)})")
            print(f"{kind:8s} {count} arrays: {how} ({args.base} against this tree)")


if __name__ == "__main__":
    main()
