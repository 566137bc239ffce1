"""An experiment's runs (Ray tasks on a local Ray) after interruptions: Ctrl-C (SIGINT) ends the driver with
one line; a rerun reuses the finished runs and resumes the others from their checkpoints; after a SIGKILL of
the driver nothing it started keeps running (Ray's dashboard and runtime-env agents stayed up to minutes);
the last rerun finishes."""
import json
import signal
import subprocess
import sys
import time

import pytest
import torch

from trainer.agent import checkpoint
from trainer.cluster import process_tree, start_time
from trainer.paths import REPO_ROOT
from trainer.scripts.cli import RUNS_INTERRUPTED

pytest.importorskip("ray", reason="Ray is a trainer dependency: pip install ray")
pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the process tree from /proc")

#: The wave run trains 12 epochs, the point-and-wave run 24.
EPOCH_SCALE = 0.24


def _driver(tiny_library, runs):
    """The experiments script's training (trainer.scripts.experiments without its evaluation) as a process."""
    code = ("import sys; from trainer.experiments.paper import PaperSettings, train_all; "
            "from trainer.scripts.cli import RUNS_INTERRUPTED, run_main; "
            f"sys.exit(run_main(train_all, PaperSettings(preset='debug', epoch_scale={EPOCH_SCALE}, "
            f"variants=('rlanimate',), columns=('wave', 'both'), clips={str(tiny_library)!r}, runs={str(runs)!r}, "
            "eval_every=0, seeds=(0,), workers=2), interrupted=RUNS_INTERRUPTED))")
    return subprocess.Popen([sys.executable, "-c", code], cwd=REPO_ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _epochs(folder):
    metrics = folder / "metrics.jsonl"
    return len(metrics.read_text().splitlines()) if metrics.is_file() else 0


def _wait_for(condition, driver, timeout=300):
    deadline = time.monotonic() + timeout
    while not condition():
        assert driver.poll() is None, f"the driver ended early: {driver.communicate()[1][-3000:]}"
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.05)


def _still_running(started, timeout):
    """The processes of `started` ({pid: start time}) still running after up to `timeout` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        running = {pid for pid, start in started.items() if start_time(pid) == start}
        if not running or time.monotonic() > deadline:
            return running
        time.sleep(0.2)


def test_interrupted_and_killed_experiments_resume_and_leave_nothing_running(tiny_library, tmp_path):
    runs = tmp_path / "runs"
    wave, both = runs / "rlanimate_wave", runs / "rlanimate_both"

    driver = _driver(tiny_library, runs)
    _wait_for(lambda: _epochs(wave) >= 2 and _epochs(both) >= 2, driver)
    started = process_tree(driver.pid)
    driver.send_signal(signal.SIGINT)
    _, error = driver.communicate(timeout=60)
    assert driver.returncode == 130 and error.strip().splitlines()[-1] == RUNS_INTERRUPTED
    assert "Traceback" not in error
    assert not _still_running(started, 10), "the driver's processes end with it"

    driver = _driver(tiny_library, runs)
    _wait_for(lambda: (wave / "report.json").is_file() and _epochs(both) >= 14, driver)
    finished_wave = {p.name: p.read_bytes() for p in wave.iterdir() if p.is_file()}
    started = process_tree(driver.pid)
    assert len(started) >= 5, "the local Ray's processes were found"
    driver.send_signal(signal.SIGKILL)
    driver.communicate(timeout=60)
    assert not _still_running(started, 10), "nothing the killed driver started keeps running"
    stopped = torch.load(both / checkpoint.FILENAME, weights_only=True)["trainer"]["history"]
    assert 0 < len(stopped) < 24

    driver = _driver(tiny_library, runs)
    output, error = driver.communicate(timeout=600)
    assert driver.returncode == 0, error[-3000:]
    assert output.splitlines() == ["finished rlanimate both seed 0"], "only the unfinished run trains again"
    assert {p.name: p.read_bytes() for p in wave.iterdir() if p.is_file()} == finished_wave, "the finished run is kept"
    metrics = [json.loads(line) for line in (both / "metrics.jsonl").read_text().splitlines()]
    assert len(metrics) == 24 and json.loads((both / "report.json").read_text())["epochs"] == 24
    assert [m["update_seconds"] for m in metrics[:len(stopped)]] == [m["update_seconds"] for m in stopped], \
        "the run continued from its checkpoint (its epochs before the kill are the same epochs)"
