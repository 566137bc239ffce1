"""Fuzz of the extension's VRM reader: seeded mutations of the real VRM 0.x robot (../shared/rigs).

Each mutation (tests/core/vrm_fuzz.py: the header's fields, truncation, the JSON chunk's bytes, text and
values, the humanoid map rewritten, nesting up to 100,000 deep, chunks of 2 to 32 MiB and thousands of
nodes) is written to a file and read with `core.vrm.file_roles` for the armature imported from the
original, as Generate and "Bone Map from VRM File" read it. Counts each outcome per kind, times each read
and measures its peak memory (tracemalloc, in a second read), names the slowest case, and writes the
section "VRM file fuzz" of docs/BENCHMARKS.md. The run fails on any outcome other than a refusal
(RLAnimateError), the original map, or a changed map read exactly as the changed JSON says with one bone
per role, and on any read over MAX_READ_SECONDS or MAX_READ_MB.

Run: `python benchmarks/vrm_fuzz_benchmark.py [--mutations 1000] [--seeds 0 1 2] [--no-write]`
"""
import argparse
import collections
import functools
import os
import platform
import statistics
import sys
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "core"))

import fuzz_runs  # noqa: E402  (benchmarks/fuzz_runs.py)
import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)

import vrm_fuzz  # noqa: E402  (tests/core/vrm_fuzz.py)
from rlanimate_addon.core import vrm  # noqa: E402

HEADING = "## VRM file fuzz"
COMMAND = "python benchmarks/vrm_fuzz_benchmark.py"
ROBOT = ROOT.parent / "shared" / "rigs" / "vrm" / "unavi_robot_vrm0.vrm"
MAX_READ_SECONDS = 1.0
MAX_READ_MB = 100.0


def fuzz(reference, seed, mutations, folder, counts, measures, failures):
    """Run `mutations` mutations of seed `seed`, adding to counts[kind][outcome] and measures[kind]
    (seconds, peak MB, seed, mutation)."""
    generator = vrm_fuzz.mutations(reference.data, np.random.default_rng(seed))
    path = Path(folder) / "mutated.vrm"
    for k in range(mutations):
        kind, data = next(generator)
        path.write_bytes(data)
        outcome = vrm_fuzz.outcome(path, reference)
        seconds, peak = fuzz_runs.seconds_and_peak_mb(lambda: vrm.file_roles(str(path), reference.bone_names))
        measures[kind].append((seconds, peak, seed, k, len(data)))
        counts[kind][outcome if outcome in vrm_fuzz.ACCEPTED else "other"] += 1
        if outcome not in vrm_fuzz.ACCEPTED:
            failures.append(f"seed {seed} mutation {k} ({kind}): {outcome}")
        if seconds > MAX_READ_SECONDS or peak > MAX_READ_MB:
            failures.append(f"seed {seed} mutation {k} ({kind}): a read of {seconds:.2f} s, {peak:.0f} MB")


def _row(label, counter, rows):
    times = (f"{1e3 * statistics.median(r[0] for r in rows):.2f} | {1e3 * max(r[0] for r in rows):.1f} | "
             f"{max(r[1] for r in rows):.1f}") if rows else "- | - | -"
    return (f"| {label} | {sum(counter.values()):,} | {counter['refused']:,} | {counter['identical']:,} | "
            f"{counter['valid other map']:,} | {counter['other']:,} | {times} |")


def section(args, counts, measures, per_seed, elapsed, peak):
    """The text of the BENCHMARKS.md section."""
    total = sum(counts.values(), collections.Counter())
    every = [(kind, r) for kind in measures for r in measures[kind]]
    slow_kind, slow = max(every, key=lambda item: item[1][0])
    big_kind, big = max(every, key=lambda item: item[1][1])
    seeds = " ".join(str(seed) for seed in args.seeds)
    return "\n".join([
        HEADING, "",
        f"{args.mutations:,} seeded mutations per seed, seeds {seeds}, of the real VRM 0.x robot "
        "(`../shared/rigs/vrm/unavi_robot_vrm0.vrm`: its 20-byte header and", "its 26 kB JSON chunk; "
        "`tests/core/vrm_fuzz.py`, whose docstring names each kind), each read by the extension's reader",
        "(`core.vrm.file_roles`, for the armature imported from the original, as Generate and Bone Map from VRM "
        "File read it). Outcomes:", "refused with an RLAnimateError; identical (the original map); a valid other "
        "map (a changed map read exactly as the changed", "JSON says, one bone per role); other (another "
        "exception, or any other map: the target is 0). Median and worst ms: one read;",
        f"worst MB: its peak memory by tracemalloc, in a second read (the bounds: {MAX_READ_SECONDS:g} s and "
        f"{MAX_READ_MB:g} MB). The reader caps the", f"JSON chunk at {vrm.MAX_JSON_BYTES:,} bytes and its "
        f"nesting at {vrm.MAX_NESTING} (uncapped, a 32 MB chunk takes 6-12 s and 1.14 GB, and 1,000 deep",
        "raises RecursionError).", "",
        f"Regenerate: `{COMMAND} --mutations {args.mutations} --seeds {seeds}`", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs, Python "
        f"{platform.python_version()}, numpy {np.__version__}. {elapsed:.1f} s in all, peak memory of the run "
        f"{peak:.0f} MB (the mutated files are built in memory). Date: "
        f"{datetime.now(UTC):%Y-%m-%d %H:%M} UTC.", "",
        "| mutation | count | refused | identical | valid other map | other | median ms | worst ms | worst MB |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        *(_row(kind, counts[kind], measures[kind]) for kind in vrm_fuzz.KINDS),
        _row("**all**", total, [r for _, r in every]), "",
        f"Slowest read: {1e3 * slow[0]:.1f} ms, seed {slow[2]} mutation {slow[3]} ({slow_kind}, a "
        f"{slow[4]:,}-byte file). Largest peak: {big[1]:.1f} MB, seed {big[2]} mutation {big[3]} ({big_kind}, "
        f"a {big[4]:,}-byte file).", "",
        "Per seed: " + "; ".join(f"seed {seed}: {sum(c.values()):,} mutations, {c['other']:,} other"
                                 for seed, c in per_seed) + ".",
    ]) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutations", type=int, default=1000, help="per seed")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    if not ROBOT.is_file():
        raise SystemExit(f"{ROBOT} is absent: the VRM fuzz reads ../shared/rigs (see its README.md)")
    reference = vrm_fuzz.Reference(ROBOT)
    runs = fuzz_runs.run_seeds(functools.partial(fuzz, reference), args.seeds, args.mutations)
    counts, measures, failures, per_seed = runs.counts, runs.measures, runs.failures, runs.per_seed
    elapsed, peak = runs.seconds, runs.peak_mb
    text = section(args, counts, measures, per_seed, elapsed, peak)
    print(text)
    for failure in failures:
        print(failure)
    if failures:
        raise SystemExit(f"{len(failures)} mutations gave another outcome or an over-long read")
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
