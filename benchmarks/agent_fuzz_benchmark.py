"""Fuzz of the extension's agent loader: 3,000 seeded mutations of the shipped agent file per seed.

Each mutation (tests/core/agent_fuzz.py: zip local headers, central directory and end record, npy
headers and their length fields, the metadata's bytes, values and text, deflate bombs, damaged
deflate data, LZMA and bzip2 repacks and method fields, entry-count bombs, weight values) is written
to a file and loaded with `core.runtime.load_agent`, as the panel and Generate Gesture load it, and
the loaded agent makes the keys of a 40-frame gesture of each behaviour it knows
(`core.gesture.gesture_rotations`). Counts each outcome per kind, times each load and measures its peak
memory (tracemalloc, which sees numpy's arrays and the bytes zipfile inflates, in a second load), and
writes the section "Agent file fuzz" of docs/BENCHMARKS.md. The run fails on any outcome other than a
refusal (RLAnimateError), an identical load, or a still-valid changed file read exactly as numpy reads
it that bakes finite keys, and on any load over MAX_LOAD_SECONDS or MAX_LOAD_MB.

Run: `python benchmarks/agent_fuzz_benchmark.py [--mutations 3000] [--seeds 0 1 2] [--no-write]`
"""
import argparse
import collections
import functools
import os
import platform
import statistics
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "core"))

import fuzz_runs  # noqa: E402  (benchmarks/fuzz_runs.py)
import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)

import agent_fuzz  # noqa: E402  (tests/core/agent_fuzz.py)
from rlanimate_addon.core import runtime  # noqa: E402

HEADING = "## Agent file fuzz"
COMMAND = "python benchmarks/agent_fuzz_benchmark.py"
SHIPPED = ROOT / "rlanimate_addon" / "agents" / "default.npz"
MAX_LOAD_SECONDS = 1.0
MAX_LOAD_MB = 300.0


def fuzz(reference, seed, mutations, folder, counts, measures, failures):
    """Run `mutations` mutations of seed `seed`, adding to counts[kind][outcome] and measures[kind]."""
    generator = agent_fuzz.mutations(reference.data, np.random.default_rng(seed))
    path = Path(folder) / "mutated.npz"
    for k in range(mutations):
        kind, data = next(generator)
        path.write_bytes(data)
        began = time.perf_counter()
        outcome = agent_fuzz.outcome(path, reference)
        elapsed = time.perf_counter() - began
        load_seconds, load_mb = fuzz_runs.seconds_and_peak_mb(lambda: runtime.load_agent(path))
        measures[kind].append((elapsed, load_seconds, load_mb, seed, k))
        counts[kind][outcome if outcome in agent_fuzz.ACCEPTED else "other"] += 1
        if outcome not in agent_fuzz.ACCEPTED:
            failures.append(f"seed {seed} mutation {k} ({kind}): {outcome}")
        if load_seconds > MAX_LOAD_SECONDS or load_mb > MAX_LOAD_MB:
            failures.append(f"seed {seed} mutation {k} ({kind}): a load of {load_seconds:.2f} s, {load_mb:.0f} MB")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutations", type=int, default=3000, help="per seed")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    reference = agent_fuzz.Reference(SHIPPED)
    runs = fuzz_runs.run_seeds(functools.partial(fuzz, reference), args.seeds, args.mutations)
    counts, measures, failures, per_seed = runs.counts, runs.measures, runs.failures, runs.per_seed
    elapsed, peak = runs.seconds, runs.peak_mb

    def row(label, counter, rows):
        return (f"| {label} | {sum(counter.values()):,} | {counter['refused']:,} | {counter['identical']:,} | "
                f"{counter['valid other file']:,} | {counter['other']:,} | "
                f"{1e3 * statistics.median(r[0] for r in rows):.2f} | {1e3 * max(r[0] for r in rows):.1f} | "
                f"{1e3 * max(r[1] for r in rows):.1f} | {max(r[2] for r in rows):.1f} |")

    total = sum(counts.values(), collections.Counter())
    every = [r for kind in measures for r in measures[kind]]
    slow_kind, slow = max(((kind, r) for kind in measures for r in measures[kind]), key=lambda item: item[1][1])
    big_kind, big = max(((kind, r) for kind in measures for r in measures[kind]), key=lambda item: item[1][2])
    seeds = " ".join(str(seed) for seed in args.seeds)
    text = "\n".join([
        HEADING, "",
        f"{args.mutations:,} seeded mutations of the shipped agent file per seed, seeds {seeds} "
        f"(`tests/core/agent_fuzz.py`, whose docstring",
        "names each kind), each loaded by the extension's loader (`core.runtime.load_agent`, which reads the",
        "file with `core/agent_file.py`), which then makes the keys of a 40-frame gesture of each behaviour the",
        "agent knows (Point and Wave, on the canonical rig). Outcomes: refused with an RLAnimateError; identical",
        "(the same weights, metadata and keys as the original); a valid other file (a mutation in a valid zip",
        "that still makes a usable agent, read exactly as numpy reads it, with finite keys); other (another",
        "exception, or a load whose keys differ or fail: the target is 0). Median and worst ms: the load and",
        "the gesture. Worst load ms and MB: the load alone, its peak memory by tracemalloc in a second load",
        f"(the bounds: {MAX_LOAD_SECONDS:g} s and {MAX_LOAD_MB:g} MB).", "",
        f"Regenerate: `{COMMAND} --mutations {args.mutations} --seeds {seeds}`", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs, Python "
        f"{platform.python_version()}, numpy {np.__version__}. {elapsed:.1f} s in all, peak memory of the run "
        f"{peak:.0f} MB (the bombs are built in memory). Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.",
        "",
        "| mutation | count | refused | identical | valid other file | other | median ms | worst ms | "
        "worst load ms | worst load MB |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *(row(kind, counts[kind], measures[kind]) for kind in agent_fuzz.KINDS),
        row("**all**", total, every), "",
        f"Slowest load: {1e3 * slow[1]:.1f} ms, seed {slow[3]} mutation {slow[4]} ({slow_kind}). Largest peak: "
        f"{big[2]:.1f} MB, seed {big[3]} mutation {big[4]} ({big_kind}).", "",
        "Per seed: " + "; ".join(f"seed {seed}: {sum(c.values()):,} mutations, {c['other']:,} other"
                                 for seed, c in per_seed) + ".",
    ]) + "\n"
    print(text)
    for failure in failures:
        print(failure)
    if failures:
        raise SystemExit(f"{len(failures)} mutations gave another outcome or an over-long load")
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
