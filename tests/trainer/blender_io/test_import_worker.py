"""Clip import in worker processes: a corrupt FBX that asks Blender for a million frames (which, imported in this
process, takes minutes and gigabytes) is skipped with a note naming the memory limit; one that takes too long is
stopped at the time limit; the import goes on, and two workers give the clips one does."""
import resource
import shutil
import struct
import time
import zlib

import numpy as np
import pytest

from trainer.blender_io import clip_import
from trainer.blender_io.import_worker import ImportLimits
from trainer.paths import CLIP_DIR

#: FBX time units per second.
FBX_TICKS = 46186158000
GOOD = ("point_left_000.fbx", "wave_right_000.fbx")


def frame_bomb(source, target, last_frame):
    """Copy the FBX `source` to `target` with one animation curve's last key moved to `last_frame`, as a few
    flipped bits in its compressed key times can: the file's size and structure stay, its animation then
    runs to that frame."""
    data = bytearray(source.read_bytes())
    start = data.find(b"KeyTime")
    while start >= 0:
        array = start + len(b"KeyTime")  # the property: type 'l', then length, encoding and compressed size
        _, _, size = struct.unpack_from("<III", data, array + 1)
        times = np.frombuffer(zlib.decompress(bytes(data[array + 13:array + 13 + size])), "<i8").copy()
        times[-1] = last_frame * FBX_TICKS // 30
        for level in range(1, 10):
            packed = zlib.compress(times.tobytes(), level)
            if len(packed) <= size:  # zlib ignores the zeros after the stream's end
                data[array + 13:array + 13 + size] = packed + bytes(size - len(packed))
                target.write_bytes(data)
                return
        start = data.find(b"KeyTime", start + 1)
    raise AssertionError(f"no key time array of {source} recompresses into its place")


def library(folder, bombs):
    """A folder of the two GOOD sample clips and the `bombs` {name: last frame} made from point_left_000."""
    folder.mkdir()
    for name in GOOD:
        shutil.copyfile(CLIP_DIR / name, folder / name)
    for name, last_frame in bombs.items():
        frame_bomb(CLIP_DIR / GOOD[0], folder / name, last_frame)
    return folder


def test_a_corrupt_fbx_that_asks_for_gigabytes_is_skipped_with_a_note_and_the_import_goes_on(tmp_path):
    folder = library(tmp_path / "clips", {"a_bomb.fbx": 2_000_000})
    assert (folder / "a_bomb.fbx").stat().st_size == (folder / GOOD[0]).stat().st_size
    start = time.perf_counter()
    clips, problems = clip_import.import_clip_directory(folder, cache_dir=tmp_path / "cache")
    seconds = time.perf_counter() - start
    assert sorted(clip.name for clip in clips) == ["point_left_000", "wave_right_000"]
    [problem] = problems
    assert problem.startswith(f"{folder / 'a_bomb.fbx'}: importing it ran out of its 2 GB of memory (")
    assert problem.endswith("raise --import-memory-limit if the clip is sound and this large.")
    assert seconds < 60, f"the import took {seconds:.0f} s"
    assert resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss < 2.5 * 2 ** 20, "no worker passed its cap (KB)"


def test_an_import_that_runs_past_the_time_limit_is_stopped_and_the_next_clip_imports(tmp_path):
    folder = library(tmp_path / "clips", {"a_slow.fbx": 20_000})  # about 40 s of frames in Blender
    start = time.perf_counter()
    clips, problems = clip_import.import_clip_directory(folder, cache_dir=tmp_path / "cache",
                                                        limits=ImportLimits(seconds=4.0))
    assert time.perf_counter() - start < 30
    assert sorted(clip.name for clip in clips) == ["point_left_000", "wave_right_000"]
    assert problems == [f"{folder / 'a_slow.fbx'}: importing it took longer than 4 s, so it was stopped and the clip "
                        "skipped (the file may be corrupt). Re-export it, or raise --import-time-limit if the clip "
                        "is sound and this long."]


@pytest.fixture(scope="module")
def serial_and_parallel(tiny_library, tmp_path_factory):
    folder = tmp_path_factory.mktemp("caches")
    return [(clip_import.import_clip_directory(tiny_library, cache_dir=folder / name, workers=workers), folder / name)
            for name, workers in (("serial", 1), ("parallel", 2))]


def test_clips_imported_by_two_workers_are_the_ones_one_worker_imports(serial_and_parallel):
    [((serial, serial_problems), serial_cache), ((parallel, parallel_problems), parallel_cache)] = serial_and_parallel
    assert len(serial) == len(parallel) == 6 and serial_problems == parallel_problems == []
    for a, b in zip(serial, parallel, strict=True):
        assert (a.name, a.behaviour, a.arm, a.fps) == (b.name, b.behaviour, b.arm, b.fps)
        assert np.array_equal(a.rotvecs, b.rotvecs) and sorted(a.fingers) == sorted(b.fingers)
        assert all(np.array_equal(a.fingers[name], b.fingers[name]) for name in a.fingers)
    cached = [sorted(p.name for p in cache.iterdir()) for cache in (serial_cache, parallel_cache)]
    assert cached[0] == cached[1] and len(cached[0]) == 6


def test_a_clip_imported_by_a_worker_is_the_clip_imported_in_this_process(serial_and_parallel, tiny_library):
    [((serial, _), _), _] = serial_and_parallel
    here = clip_import.import_clip(tiny_library.parent / f"{serial[0].name}.fbx")
    assert np.array_equal(here.rotvecs, serial[0].rotvecs)
