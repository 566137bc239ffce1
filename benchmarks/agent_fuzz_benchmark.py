"""Fuzz of the extension's agent loader: 3,000 seeded mutations of the shipped agent file.

Each mutation (tests/core/agent_fuzz.py: zip local headers, central directory and end record, npy
headers, the metadata's bytes, values and text, deflate bombs) is written to a file and loaded with
`core.runtime.load_agent`, as the panel and Generate Gesture load it, and the loaded agent makes the
keys of a 40-frame gesture of each behaviour it knows (`core.gesture.gesture_rotations`). Counts each outcome per kind, times each load, and writes the section "Agent file fuzz" of
docs/BENCHMARKS.md. Any outcome other than a refusal (RLAnimateError), an identical load, or a
still-valid changed file read exactly as numpy reads it that bakes finite keys, fails the run.

Run: `python benchmarks/agent_fuzz_benchmark.py [--mutations 3000] [--seed 0] [--no-write]`
"""
import argparse
import collections
import os
import platform
import resource
import statistics
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "core"))

import numpy as np  # noqa: E402

import agent_fuzz  # noqa: E402  (tests/core/agent_fuzz.py)
import report  # noqa: E402  (benchmarks/report.py)

HEADING = "## Agent file fuzz"
COMMAND = "python benchmarks/agent_fuzz_benchmark.py"
SHIPPED = ROOT / "rlanimate_addon" / "agents" / "default.npz"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutations", type=int, default=3000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-write", action="store_true", help="print the section only")
    args = parser.parse_args()
    reference = agent_fuzz.Reference(SHIPPED)
    generator = agent_fuzz.mutations(reference.data, np.random.default_rng(args.seed))
    counts = collections.defaultdict(collections.Counter)  # kind -> outcome -> count
    times = collections.defaultdict(list)  # kind -> seconds per load
    failures = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "mutated.npz"
        for k in range(args.mutations):
            kind, data = next(generator)
            path.write_bytes(data)
            began = time.perf_counter()
            outcome = agent_fuzz.outcome(path, reference)
            times[kind].append(time.perf_counter() - began)
            counts[kind][outcome if outcome in agent_fuzz.ACCEPTED else "other"] += 1
            if outcome not in agent_fuzz.ACCEPTED:
                failures.append(f"mutation {k} ({kind}): {outcome}")
    elapsed = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # MB (Linux reports kB)

    def row(label, counter, seconds):
        return (f"| {label} | {sum(counter.values()):,} | {counter['refused']:,} | {counter['identical']:,} | "
                f"{counter['valid other file']:,} | {counter['other']:,} | {1e3 * statistics.median(seconds):.2f} | "
                f"{1e3 * max(seconds):.1f} |")

    total = sum(counts.values(), collections.Counter())
    every = [t for kind in times for t in times[kind]]
    text = "\n".join([
        HEADING, "",
        f"{args.mutations:,} seeded mutations of the shipped agent file (`tests/core/agent_fuzz.py`), each loaded by",
        "the extension's loader (`core.runtime.load_agent`, which reads the file with `core/agent_file.py`), which",
        "then makes the keys of a 40-frame gesture of each behaviour the agent knows (Point and Wave, on the",
        "canonical rig). Outcomes: refused with an RLAnimateError; identical (the same weights, metadata and",
        "keys as the original); a valid other file (a mutation in a valid zip that still makes a usable agent,",
        "read exactly as numpy reads it, with finite keys); other (another exception, or a load whose keys",
        "differ or fail: the target is 0). Times are per load and gesture.", "",
        f"Regenerate: `{COMMAND} --mutations {args.mutations} --seed {args.seed}`", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs, Python "
        f"{platform.python_version()}, numpy {np.__version__}. {elapsed:.1f} s in all, peak memory "
        f"{peak:.0f} MB (the 64 MB deflate bombs are built in memory). "
        f"Date: {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC.", "",
        "| mutation | count | refused | identical | valid other file | other | median ms | worst ms |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
        *(row(kind, counts[kind], times[kind]) for kind in agent_fuzz.KINDS),
        row("**all**", total, every),
    ]) + "\n"
    print(text)
    for failure in failures:
        print(failure)
    if failures:
        raise SystemExit(f"{len(failures)} mutations gave another outcome")
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
