"""Wall time of the whole test suite on Blender 5.0, as `scripts/run_tests.sh` runs it (test files spread
over every core by pytest-xdist) and in one process, interleaved in pairs so that drift in the shared
machine's speed falls on both. Writes the section "Test suite" of docs/BENCHMARKS.md.

Run: `python benchmarks/suite_benchmark.py [--pairs N] [--no-write]`
"""
import argparse
import os
import platform
import statistics
import subprocess
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import report  # noqa: E402  (benchmarks/report.py)

HEADING = "## Test suite"
COMMAND = "python benchmarks/suite_benchmark.py"
WAYS = {"one process": ["-n", "0"], "run_tests.sh (one worker per core)": ["-n", "auto", "--dist", "loadfile"]}
BASELINE_S = 90.0  # the single-process suite when issue 9 was filed


def suite_seconds(options):
    """Wall seconds of one whole-suite run with these pytest options; the run must pass."""
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *options], cwd=ROOT,
                            capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"the suite failed with {options}:\n{result.stdout[-2000:]}")
    print(f"{' '.join(options)}: {seconds:.1f} s, {result.stdout.strip().splitlines()[-1]}", flush=True)
    return seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=3, help="runs of each way, interleaved (default 3)")
    parser.add_argument("--no-write", action="store_true", help="print the section, leave docs/BENCHMARKS.md")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    times = {way: [] for way in WAYS}
    for _ in range(args.pairs):
        for way, options in WAYS.items():
            times[way].append(suite_seconds(options))
    import bpy

    rows = "\n".join(f"| {way} | {statistics.median(t):.1f} | {min(t):.1f} | {max(t):.1f} | "
                     f"{1 - statistics.median(t) / BASELINE_S:.0%} |" for way, t in times.items())
    ratios = [a / b for a, b in zip(*times.values(), strict=True)]
    text = f"""{HEADING}

Wall seconds of `python -m pytest -q` (the whole suite on Blender 5.0) in one process and as
`scripts/run_tests.sh` runs it, with test files spread over every core (pytest-xdist, `--dist loadfile`,
so each file's module fixtures are built once); {args.pairs} interleaved pairs. "Faster" is against a 90 s
baseline (the single-process suite of an early tree).

Regenerate: `{COMMAND}`

Machine: {platform.machine()}, {os.cpu_count()} CPU cores, Python {platform.python_version()}, bpy {bpy.app.version_string}, load average {load:.1f} at start. Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.

| way | median s | min s | max s | faster than 90 s |
|---|---:|---:|---:|---:|
{rows}

One process over one worker per core, pair by pair: {statistics.median(ratios):.2f}x (min {min(ratios):.2f}, max {max(ratios):.2f}).
"""
    print(text)
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
