"""Fuzz of clip manifests through the trainer's importer: seeded mutations of a 4-clip library's manifest.

Each mutation (tests/trainer/motion/manifest_fuzz.py: wrong types and out-of-range values at every field,
fields removed, entries that are not objects, a wrong top level, JSON nested up to 100,000 deep, flipped,
cut, BOM-prefixed and latin-1 bytes) is written over the manifest of 4 of the sample library's clips and
loaded by `trainer.blender_io.clip_import.import_clip_directory`, as training loads a library (the clips
are imported once, then come from the import cache). Counts each outcome per kind and writes the section
"Clip manifest fuzz" of docs/BENCHMARKS.md. A traceback, a note or refusal that names neither the
manifest entry nor the file, or an accepted clip whose labels do not make a finite objective fails the run.

Run: `python benchmarks/manifest_fuzz_benchmark.py [--mutations 1000] [--seeds 0 1 2] [--no-write]`
"""
import argparse
import collections
import os
import platform
import statistics
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "trainer" / "motion"))

import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)

import manifest_fuzz  # noqa: E402  (tests/trainer/motion/manifest_fuzz.py)
from trainer.blender_io import clip_import  # noqa: E402
from trainer.blender_io.rig_session import blender_output  # noqa: E402

HEADING = "## Clip manifest fuzz"
COMMAND = "python benchmarks/manifest_fuzz_benchmark.py"
OUTCOMES = ("refused", "skipped", "accepted", "failure")


def run_seed(seed, mutations, counts, times, failures):
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        manifest = manifest_fuzz.small_library(folder)
        path = folder / "manifest.json"
        with blender_output():  # Blender's importer prints, as training holds them back
            clips, problems = clip_import.import_clip_directory(path)
        assert len(clips) == 4 and problems == [], problems
        generator = manifest_fuzz.mutations(manifest, np.random.default_rng(seed))
        for k in range(mutations):
            kind, data = next(generator)
            path.write_bytes(data)
            began = time.perf_counter()
            with blender_output():
                outcome = manifest_fuzz.outcome(path, clip_import.import_clip_directory)
            times[kind].append(time.perf_counter() - began)
            counts[kind][outcome if outcome in manifest_fuzz.ACCEPTED else "failure"] += 1
            if outcome not in manifest_fuzz.ACCEPTED:
                failures.append(f"seed {seed}, mutation {k} ({kind}): {outcome}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutations", type=int, default=1000, help="per seed")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    counts = collections.defaultdict(collections.Counter)  # kind -> outcome -> count
    times = collections.defaultdict(list)  # kind -> seconds per load
    failures = []
    start = time.perf_counter()
    for seed in args.seeds:
        run_seed(seed, args.mutations, counts, times, failures)
    elapsed = time.perf_counter() - start

    def row(label, counter, seconds):
        return (f"| {label} | {sum(counter.values()):,} | " + " | ".join(f"{counter[o]:,}" for o in OUTCOMES)
                + f" | {1e3 * statistics.median(seconds):.1f} | {1e3 * max(seconds):.0f} |")

    total = sum(counts.values(), collections.Counter())
    every = [t for kind in times for t in times[kind]]
    seeds = " ".join(str(s) for s in args.seeds)
    text = "\n".join([
        HEADING, "",
        f"{args.mutations:,} seeded mutations per seed (seeds {seeds}) of the manifest of 4 of the sample library's",
        "clips (`tests/trainer/motion/manifest_fuzz.py`), each loaded by the trainer's importer",
        "(`clip_import.import_clip_directory`, which checks every entry with `trainer/motion/manifest.py` before",
        "importing anything; the clips come from the import cache after the first load). Outcomes: refused (an",
        "RLAnimateError naming the manifest); skipped (the bad entries skipped, each with a note naming the",
        "manifest, the entry and the field, or the clip file that did not import); accepted (every clip loaded,",
        "with labels that make a finite objective); failure (a traceback, a vague note, or labels that cannot",
        "train: the target is 0). Times are per load.", "",
        f"Regenerate: `{COMMAND} --mutations {args.mutations} --seeds {seeds}`", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs, Python "
        f"{platform.python_version()}, numpy {np.__version__}. {elapsed:.1f} s in all. "
        f"Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.", "",
        "| mutation | count | refused | skipped | accepted | failure | median ms | worst ms |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
        *(row(kind, counts[kind], times[kind]) for kind in manifest_fuzz.KINDS),
        row("**all**", total, every),
    ]) + "\n"
    print(text)
    for failure in failures:
        print(failure)
    if failures:
        raise SystemExit(f"{len(failures)} mutations gave a failure")
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
