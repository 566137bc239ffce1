"""Workers against wall time: the clip import of the sample library (and of the real capture, when it is
beside the repository) into a fresh cache by import worker processes, and a small Table 4 (debug preset)
trained as Ray tasks. Each
worker count gets a fresh local Ray, started before the clock runs; the agents trained with every count
are compared array by array. Writes the section "Ray workers" of docs/BENCHMARKS.md.

Run: `python benchmarks/ray_benchmark.py [--workers 1 2] [--no-realmocap] [--no-write]`
"""
import argparse
import os
import platform
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import ray  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)

from trainer.blender_io.clip_import import EXPECTED_FPS, import_clip_directory  # noqa: E402
from trainer.blender_io.import_worker import import_into_cache  # noqa: E402
from trainer.cluster import connect  # noqa: E402
from trainer.experiments.paper import COLUMNS, PaperSettings, run_folder, train_all  # noqa: E402
from trainer.motion.realmocap_takes import take_paths  # noqa: E402
from trainer.paths import DEFAULT_MANIFEST, REALMOCAP_DIR  # noqa: E402

HEADING = "## Ray workers"
COMMAND = "python benchmarks/ray_benchmark.py"
#: The small Table 4: debug preset, 5 / 10 epochs (0.1 x the paper's), one seed, two variants, every column.
TABLE4 = dict(preset="debug", epoch_scale=0.1, seeds=(0,), variants=("rlanimate", "supervised"), columns=COLUMNS,
              eval_every=5)


def fresh_ray(workers):
    """A local Ray of `workers` CPUs, started (seconds returned) before anything is timed."""
    ray.shutdown()
    start = time.perf_counter()
    connect(workers=workers)
    return time.perf_counter() - start


def import_seconds(workers, folder):
    """Wall seconds to import the sample library into a fresh cache in `folder` with `workers` import workers."""
    start = time.perf_counter()
    clips, problems = import_clip_directory(DEFAULT_MANIFEST, cache_dir=folder, workers=workers)
    assert clips and not problems, problems
    return time.perf_counter() - start, len(clips)


def realmocap_seconds(workers, folder):
    """Wall seconds to import every real take (wave/, bye/, guide/) into a fresh cache with `workers` import
    workers; and the number of takes."""
    files = [(p, EXPECTED_FPS) for sub in ("wave", "bye", "guide") for p in take_paths(REALMOCAP_DIR / sub)]
    start = time.perf_counter()
    assert not import_into_cache(files, folder, workers)
    return time.perf_counter() - start, len(files)


def table4_seconds(workers, runs):
    settings = PaperSettings(runs=str(runs), workers=workers, **TABLE4)
    start = time.perf_counter()
    train_all(settings)
    return time.perf_counter() - start, settings


def agents_equal(first, second):
    """Whether every run's agent.npz holds the same arrays in the two Table 4 trainings."""
    for seed in first.seeds:
        for variant in first.variants:
            for column in first.columns:
                with np.load(run_folder(first, seed, variant, column) / "agent.npz") as a, \
                        np.load(run_folder(second, seed, variant, column) / "agent.npz") as b:
                    if any(not np.array_equal(a[k], b[k]) for k in a.files if a[k].dtype.kind == "f"):
                        return False
    return True


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--no-realmocap", action="store_true", help="leave out the real capture's import")
    parser.add_argument("--no-write", action="store_true", help="print the section, leave docs/BENCHMARKS.md")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    realmocap = not args.no_realmocap and (REALMOCAP_DIR / "wave").is_dir()
    rows, trained = [], []
    with tempfile.TemporaryDirectory() as scratch:
        for workers in args.workers:
            ray_start = fresh_ray(workers)
            clips_s, clip_count = import_seconds(workers, Path(scratch) / f"cache{workers}")
            real = realmocap_seconds(workers, Path(scratch) / f"real{workers}") if realmocap else None
            table_s, settings = table4_seconds(workers, Path(scratch) / f"runs{workers}" / "experiments")
            trained.append(settings)
            rows.append(f"| {workers} | {ray_start:.1f} | {clips_s:.1f} ({clip_count / clips_s:.1f} clips/s) | "
                        + (f"{real[0]:.1f} ({real[1] / real[0]:.1f} takes/s) | " if real else "")
                        + f"{table_s:.1f} |")
            print(rows[-1], flush=True)
        same = all(agents_equal(trained[0], other) for other in trained[1:])
    ray.shutdown()
    import bpy

    runs = len(TABLE4["seeds"]) * len(TABLE4["variants"]) * len(TABLE4["columns"])
    real_header = " real capture import (s) |" if realmocap else ""
    text = (
        f"""{HEADING}

Wall seconds against the number of local Ray workers (`trainer/cluster.py`): importing the sample library's
{clip_count} FBX clips into a fresh cache (N import worker processes, each its own Blender, for N
workers; trainer/blender_io/import_worker.py){", and the real capture's BVH takes (wave/, bye/, guide/)" if realmocap else ""}; and training a small Table 4,
{runs} runs (preset `debug`, 0.1 x the paper's epochs, seed 0, `rlanimate` and `supervised`, every column) as
Ray tasks. Ray's start is timed apart. The agents trained with every worker count are
{"identical, array by array" if same else "NOT identical"}.
A worker count only pays where that many cores are free: each training task also starts a fresh
process that imports bpy and torch and loads the library from the cache (about 20 s), and on a
machine whose load already exceeds its cores two workers share what one had.

Regenerate: `{COMMAND}`

Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs (load average {load:.1f} at start), Python {platform.python_version()}, bpy {bpy.app.version_string}, Ray {ray.__version__}. Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.

| workers | Ray start (s) | sample library import (s) |{real_header} small Table 4 training (s) |
|---:|---:|---:|{"---:|" if realmocap else ""}---:|
"""
        + "\n".join(rows)
        + "\n"
    )
    print(text)
    if not args.no_write:
        report.write_section(HEADING, text)


if __name__ == "__main__":
    main()
