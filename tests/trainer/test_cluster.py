"""Ray tasks (trainer/cluster.py) give what the serial code gives: a training run on a Ray worker is bit for
bit the run trained in this process, and clips imported by two Blenders at once are the serial import's,
in the same cache."""
import numpy as np
import pytest

from trainer.blender_io.clip_import import import_clip_directory
from trainer.blender_io.clip_session import LibrarySession
from trainer.cluster import connect
from trainer.experiments.run import RunSettings, train, train_runs

ray = pytest.importorskip("ray", reason="Ray is a trainer dependency: pip install ray")


@pytest.fixture(scope="module")
def local_ray():
    connect(workers=2)
    yield
    ray.shutdown()


def test_a_run_on_a_ray_worker_equals_the_run_in_this_process(tiny_library, tmp_path, local_ray):
    def run(output):
        return RunSettings(output=str(output), behaviour="both", clips=str(tiny_library), epochs=2, seed=5,
                           preset="debug", eval_every=0, progress=False)

    train(run(tmp_path / "serial"), LibrarySession(tiny_library))
    [(settings, report)] = list(train_runs([run(tmp_path / "ray")]))
    assert settings.output == str(tmp_path / "ray") and report["epochs"] == 2
    assert "clips:" in (tmp_path / "ray" / "train.log").read_text()  # the worker's output went to the run's log
    with np.load(tmp_path / "serial" / "agent.npz") as serial, np.load(tmp_path / "ray" / "agent.npz") as remote:
        weights = [name for name in serial.files if serial[name].dtype.kind == "f"]
        assert len(weights) > 10 and sorted(serial.files) == sorted(remote.files)
        assert all(np.array_equal(serial[name], remote[name]) for name in weights)


def test_clips_imported_by_two_blenders_are_the_serial_import_in_the_same_cache(tiny_library, tmp_path, local_ray):
    serial, serial_problems = import_clip_directory(tiny_library, cache_dir=tmp_path / "serial")
    parallel, parallel_problems = import_clip_directory(tiny_library, cache_dir=tmp_path / "parallel", workers=2)
    assert len(serial) == len(parallel) == 6 and serial_problems == parallel_problems == []
    for a, b in zip(serial, parallel):
        assert (a.name, a.behaviour, a.arm, a.fps) == (b.name, b.behaviour, b.arm, b.fps)
        assert np.array_equal(a.rotvecs, b.rotvecs) and sorted(a.fingers) == sorted(b.fingers)
        assert all(np.array_equal(a.fingers[name], b.fingers[name]) for name in a.fingers)
    cached = [sorted(p.name for p in (tmp_path / name).iterdir()) for name in ("serial", "parallel")]
    assert cached[0] == cached[1] and len(cached[0]) == 6
