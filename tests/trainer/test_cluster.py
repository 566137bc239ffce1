"""Ray tasks (trainer/cluster.py) give what the serial code gives: a training run on a Ray worker is bit for
bit the run trained in this process (on the sample library and on real capture); a run refused on a worker
is one line naming it."""
import numpy as np
import pytest

from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io.clip_session import LibrarySession
from trainer.cluster import connect
from trainer.experiments import realmocap
from trainer.experiments.run import RunSettings, train, train_runs
from trainer.paths import REALMOCAP_DIR

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
    assert _agents_equal(tmp_path / "serial", tmp_path / "ray")


def test_a_run_refused_on_a_ray_worker_is_one_line_naming_the_run(tiny_library, tmp_path, local_ray):
    output = tmp_path / "run"
    output.mkdir()
    (output / "checkpoint.pt").write_bytes(b"not a checkpoint")
    settings = RunSettings(output=str(output), clips=str(tiny_library), epochs=2, preset="debug", resume=True,
                           progress=False)
    with pytest.raises(RLAnimateError) as refused:
        list(train_runs([settings]))
    message = str(refused.value)
    assert message.startswith(f"The run in {output}: The checkpoint {output / 'checkpoint.pt'} is damaged (")
    assert "\n" not in message and "weights_only" not in message and "Traceback" not in message
    assert (output / "checkpoint.pt").read_bytes() == b"not a checkpoint", "the run's files are kept"


def _agents_equal(folder_a, folder_b):
    with np.load(folder_a / "agent.npz") as a, np.load(folder_b / "agent.npz") as b:
        weights = [name for name in a.files if a[name].dtype.kind == "f"]
        return len(weights) > 10 and sorted(a.files) == sorted(b.files) and all(
            np.array_equal(a[name], b[name]) for name in weights)


@pytest.mark.skipif(
    not (REALMOCAP_DIR / "wave").is_dir(),
    reason=f"real motion capture not found at {REALMOCAP_DIR} (../shared/realmocap/ beside the repository)",
)
def test_a_real_capture_run_on_a_ray_worker_equals_the_run_in_this_process(tmp_path, local_ray):
    wave = REALMOCAP_DIR / "wave"
    train_takes = tuple(str(wave / f"dataset-2_wave-left-hand_{name}.bvh") for name in ("feminine_001", "active_021"))
    test_takes = (str(wave / "dataset-2_wave-left-hand_normal_009.bvh"),)

    def run(output):
        settings = RunSettings(output=str(output), behaviour="wave", clips="realmocap:tiny", epochs=2, seed=3,
                               preset="debug", variant="rlanimate", eval_every=0, progress=False)
        return realmocap.RealRun(settings, train_takes, test_takes, str(tmp_path / "cache"))

    serial = run(tmp_path / "serial")
    report, _ = train(serial.settings, realmocap.real_session(serial.train_takes, serial.test_takes, serial.cache))
    reports = realmocap.train_real_runs([run(tmp_path / "ray")])
    remote = reports[str(tmp_path / "ray")]
    assert remote["episodes"] == report["episodes"] == 2 and remote["held_out"]["score"] == report["held_out"]["score"]
    assert (tmp_path / "ray" / "train.log").is_file()  # the worker's output went to the run's log
    assert _agents_equal(tmp_path / "serial", tmp_path / "ray")
    # A finished run is not trained again: its report is read back.
    assert realmocap.train_real_runs([run(tmp_path / "ray")]) == reports
