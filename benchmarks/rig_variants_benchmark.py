"""Generate Gesture on every rig variant of tests/addon/rig_variants.py, with more targets than the tests.

Per variant: the miss of Point (degrees between the rig's finger line and the line from its base to the
target, median over the pointing hold as docs/METRICS.md defines it) over random unseen targets, both
arms alternating, with Exact Aim on and off (off: the agent's own aim as retargeted to that rig), and a
wave's side-to-side swing in arm lengths. Writes the "Rig variants" section of docs/BENCHMARKS.md.

Run: `nice -n 10 python benchmarks/rig_variants_benchmark.py [--targets 60] [--seed 5] [--no-write]`
"""
import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "tests", ROOT / "tests" / "addon"):
    sys.path.insert(0, str(path))

import bpy  # noqa: E402
from report import write_section  # noqa: E402  (benchmarks/report.py)

import addon_helpers as helpers  # noqa: E402
import rig_variants  # noqa: E402
import test_rig_variants as measures  # noqa: E402

FRAMES = 120


def point_misses(path, targets, exact):
    """Misses at the hold (degrees) of `targets` Point gestures on the variant saved at path."""
    settings = helpers.enable_addon()
    misses = measures.point_misses(rig_variants.load(path), settings, targets, exact, measures.RNG, FRAMES)
    helpers.disable_addon()
    return misses


def wave_swing(path):
    settings = helpers.enable_addon()
    rig = rig_variants.load(path)
    assert helpers.generate(rig, settings, behaviour="WAVE", arm="RIGHT", exaggeration=0.8, start_frame=20,
                            frame_count=150) == {"FINISHED"}
    lateral = measures._lateral_wrist(rig, np.arange(20, 170))[30:-30]
    helpers.disable_addon()
    return np.ptp(lateral), measures._strokes(measures._lateral_wrist(rig, np.arange(20, 170)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=60)
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args()
    measures.RNG = np.random.default_rng(args.seed)
    folder = Path(tempfile.mkdtemp())
    rows = []
    started = time.perf_counter()
    for name in rig_variants.BUILDERS:
        path = rig_variants.build(name, folder)
        exact, raw = point_misses(path, args.targets, True), point_misses(path, args.targets, False)
        swing, strokes = wave_swing(path)
        rows.append(f"| {name} | {np.median(exact):.2f} / {exact.max():.2f} | {np.median(raw):.1f} / {raw.max():.1f} "
                    f"| {strokes} | {swing:.3f} |")
        print(rows[-1], flush=True)
    text = "\n".join([
        "## Rig variants",
        "",
        f"Generate Gesture on each rig variant built by `tests/addon/rig_variants.py`: {args.targets} random "
        f"unseen Point targets per variant (1.5-4 m, both arms alternating, {FRAMES} frames, seed {args.seed}),",
        "miss at the hold in degrees (median over the pointing hold, docs/METRICS.md; median / worst over the",
        "targets) with Exact Aim on and off, and a 150-frame wave's strokes and",
        "side-to-side swing in arm lengths at full weight. Bundled agent.",
        "",
        "Regenerate: `nice -n 10 python benchmarks/rig_variants_benchmark.py`",
        "",
        f"Blender {bpy.app.version_string}, {time.perf_counter() - started:.0f} s. "
        f"Date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.",
        "",
        "| variant | exact aim: median / worst deg | agent's own aim: median / worst deg | wave strokes | wave swing |",
        "|---|---:|---:|---:|---:|",
        *rows,
    ])
    print(text)
    if not args.no_write:
        write_section("## Rig variants", text)


if __name__ == "__main__":
    main()
