"""Fuzz of FBX clips through the trainer's import workers: seeded mutations of two sample-library clips.

Each mutation is one of: bytes flipped at random; an array's length field set to a large number (Blender's FBX
parser sizes its decompression buffer by it); an element's property count set to a large number (the parser
allocates a byte per property); an animation curve's last key moved to a random frame up to 10 million
(tests/trainer/blender_io/test_import_worker.py's frame bomb: Blender then animates that many frames); the
file cut short. The mutated files are imported as a library's clips are (trainer/blender_io/import_worker.py,
one worker, the default 2 GB memory cap, a time limit of --seconds), and each outcome is counted per kind:
imported, refused with the importer's reason (a note naming the file), skipped at the memory cap, skipped at
the time limit, skipped when Blender's process ended (a crash), or a failure (an error in the importer's own
code, or a note that does not name the file), which fails the run. Writes the section "Clip import fuzz" of
docs/BENCHMARKS.md.

Run: `python benchmarks/clip_import_fuzz_benchmark.py [--mutations 60] [--seeds 0 1 2] [--seconds 10] [--no-write]`
"""
import argparse
import collections
import os
import platform
import resource
import struct
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "tests" / "trainer" / "blender_io"))

import numpy as np  # noqa: E402
import report  # noqa: E402  (benchmarks/report.py)
from test_import_worker import frame_bomb  # noqa: E402  (tests/trainer/blender_io/test_import_worker.py)

from trainer.blender_io.import_worker import ImportLimits, import_into_cache  # noqa: E402
from trainer.blender_io.rig_session import blender_output  # noqa: E402
from trainer.paths import CLIP_DIR  # noqa: E402

HEADING = "## Clip import fuzz"
COMMAND = "python benchmarks/clip_import_fuzz_benchmark.py"
SOURCES = ("point_left_000.fbx", "wave_right_000.fbx")
KINDS = ("flipped bytes", "array length", "property count", "key frame", "cut short")
OUTCOMES = ("imported", "refused", "memory cap", "time limit", "worker ended", "failure")


def mutate(kind, data, rng, source, target):
    """Write the mutation `kind` of the FBX bytes `data` (of the file `source`) to `target`."""
    data = bytearray(data)
    if kind == "flipped bytes":
        for offset in rng.integers(27, len(data), size=int(rng.integers(1, 17))):
            data[offset] ^= 1 << int(rng.integers(8))
    elif kind in ("array length", "property count"):
        offsets = _array_offsets(data) if kind == "array length" else _element_offsets(data)
        offset = int(rng.choice(offsets))
        struct.pack_into("<I", data, offset, int(rng.integers(2 ** 24, 2 ** 32)))
    elif kind == "key frame":
        frame_bomb(source, target, int(10 ** rng.uniform(3, 7)))
        return
    else:
        del data[int(rng.integers(27, len(data))):]
    target.write_bytes(data)


def _array_offsets(data):
    """Offsets of the length field of every compressed array property (type d, f, i, l; zlib stream after)."""
    return [k + 1 for k in range(len(data) - 14) if data[k] in b"dfil" and data[k + 13] == 0x78
            and struct.unpack_from("<I", data, k + 5)[0] == 1]


def _element_offsets(data):
    """Offsets of the property-count field of the elements named like an FBX node (FBX 7.4 headers)."""
    offsets = []
    for k in range(27, len(data) - 13):
        end, count, _, size = struct.unpack_from("<IIIB", data, k)
        name = bytes(data[k + 13:k + 13 + size])
        if k < end <= len(data) and 0 < count < 100 and 2 < size < 20 and name.isalpha() and name[:1].isupper():
            offsets.append(k + 4)
    return offsets


def classify(path, problem):
    if problem is None:
        return "imported"
    text = str(problem)
    if not text.startswith(str(path)):
        return "failure"
    if "ran out of its" in text:
        return "memory cap"
    if "took longer than" in text:
        return "time limit"
    if "ended Blender's process" in text:
        return "worker ended"
    return "refused"


def run_seed(seed, mutations, seconds, counts, failures):
    rng = np.random.default_rng(seed)
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        files = []
        for k in range(mutations):
            kind, source = KINDS[k % len(KINDS)], CLIP_DIR / SOURCES[k % len(SOURCES)]
            target = folder / f"{k:04d}_{kind.replace(' ', '_')}.fbx"
            mutate(kind, source.read_bytes(), rng, source, target)
            files.append((kind, target))
        try:
            with blender_output():
                failed = import_into_cache([(path, 30.0) for _, path in files], folder / "cache", 1,
                                           ImportLimits(seconds=seconds))
        except RuntimeError as error:  # an error in the importer's own code
            failures.append(f"seed {seed}: {str(error).splitlines()[0]}")
            return
        for kind, path in files:
            outcome = classify(path, failed.get((path, 30.0)))
            counts[kind][outcome] += 1
            if outcome == "failure":
                failures.append(f"seed {seed}, {path.name}: {failed[path, 30.0]}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutations", type=int, default=60, help="per seed")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--seconds", type=float, default=10.0, help="the time limit of one clip's import")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args()
    load, start = os.getloadavg()[0], time.perf_counter()
    counts = collections.defaultdict(collections.Counter)
    failures = []
    for seed in args.seeds:
        run_seed(seed, args.mutations, args.seconds, counts, failures)
    wall = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 2 ** 20
    rows = [f"| {kind} | " + " | ".join(str(counts[kind][o]) for o in OUTCOMES) + " |" for kind in KINDS]
    total = sum(sum(c.values()) for c in counts.values())
    import bpy
    text = f"""{HEADING}

{args.mutations} seeded mutations per seed (seeds {", ".join(map(str, args.seeds))}: {total} files) of two sample
clips ({", ".join(SOURCES)}), each imported as a library's clips are: by an import worker (one; the default
2 GB memory cap; a time limit of {args.seconds:g} s), `trainer/blender_io/import_worker.py`. Imported: the clip
read; refused: a note with the importer's reason, naming the file; memory cap and time limit: skipped with a
note naming the limit; worker ended: skipped when Blender's process ended (a crash). A failure is an error in
the importer's own code or a note that does not name the file.

Regenerate: `{COMMAND} --mutations {args.mutations} --seeds {" ".join(map(str, args.seeds))} --seconds {args.seconds:g}`

Machine: {platform.machine()}, {os.cpu_count()} CPU cores shared with other jobs (load average {load:.1f} at start),
Python {platform.python_version()}, bpy {bpy.app.version_string}. {wall:.0f} s wall. Peak memory of any worker:
{peak:.2f} GB. Date: {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.

| mutation | {" | ".join(OUTCOMES)} |
|---|{"---:|" * len(OUTCOMES)}
{chr(10).join(rows)}

Failures: {len(failures)}.{"" if not failures else chr(10) + chr(10).join("- " + f for f in failures[:20])}
"""
    print(text)
    if not args.no_write:
        report.write_section(HEADING, text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
