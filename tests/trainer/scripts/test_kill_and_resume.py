"""A debug run of trainer/train.py killed (SIGKILL) three times at seeded random points and resumed each time
finishes with the uninterrupted run's weights, optimiser state and losses, bit for bit."""
import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import torch

from trainer.agent import checkpoint
from trainer.paths import REPO_ROOT

EPOCHS = 10


def _command(tiny_library, output, *extra):
    return [sys.executable, str(REPO_ROOT / "trainer" / "train.py"), "--preset", "debug", "--clips", str(tiny_library),
            "--epochs", str(EPOCHS), "--eval-every", "5", "--seed", "7", "--quiet", "--output", str(output), *extra]


def _epochs_logged(output):
    metrics = output / "metrics.jsonl"
    return len(metrics.read_text().splitlines()) if metrics.is_file() else 0


def _start(tiny_library, output):
    """The run, resumed when it has a checkpoint (as the experiments resume theirs)."""
    resume = ["--resume"] if (output / checkpoint.FILENAME).is_file() else []
    return subprocess.Popen(_command(tiny_library, output, *resume), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)


def _kill_after(process, output, epochs, delay):
    """SIGKILL `process` `delay` seconds after its metrics log reaches `epochs` lines (mid-epoch, or in the
    middle of writing its checkpoint); False when it finished first."""
    while _epochs_logged(output) < epochs:
        if process.poll() is not None:
            return False
        time.sleep(0.005)
    time.sleep(delay)
    process.send_signal(signal.SIGKILL)
    process.wait()
    return process.returncode == -signal.SIGKILL


@pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL is POSIX")
def test_three_kills_and_resumes_give_the_uninterrupted_run_bit_for_bit(tiny_library, tmp_path):
    straight = tmp_path / "straight"
    done = subprocess.run(_command(tiny_library, straight), capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]

    rng = np.random.default_rng(44)
    kill_epochs = sorted(rng.choice(np.arange(1, EPOCHS - 2), size=3, replace=False).tolist())
    delays = rng.uniform(0.0, 0.05, size=3)
    killed = tmp_path / "killed"
    for epochs, delay in zip(kill_epochs, delays, strict=True):
        process = _start(tiny_library, killed)
        assert _kill_after(process, killed, epochs, delay), f"the run finished before the kill after epoch {epochs}"
    process = _start(tiny_library, killed)
    assert process.wait(timeout=600) == 0, process.stderr.read()[-3000:]

    a = torch.load(straight / checkpoint.FILENAME, weights_only=True)["trainer"]
    b = torch.load(killed / checkpoint.FILENAME, weights_only=True)["trainer"]
    assert a["epoch"] == b["epoch"] == EPOCHS
    assert a["agent"].keys() == b["agent"].keys()
    assert all(torch.equal(a["agent"][k], b["agent"][k]) for k in a["agent"]), "the weights differ"
    for state_a, state_b in zip(a["optimizer"]["state"].values(), b["optimizer"]["state"].values(), strict=True):
        assert all(torch.equal(state_a[k], state_b[k]) for k in state_a), "the optimiser state differs"
    losses = [[{k: v for k, v in json.loads(line).items() if k.startswith(("loss/", "seen/", "unseen/"))}
               for line in (folder / "metrics.jsonl").read_text().splitlines()] for folder in (straight, killed)]
    assert losses[0] == losses[1] and len(losses[0]) == EPOCHS
    agents = [np.load(folder / "agent.npz") for folder in (straight, killed)]
    weights = [name for name in agents[0].files if name != "__metadata__"]
    assert weights and all(np.array_equal(agents[0][name], agents[1][name]) for name in weights)
    assert not list(killed.glob(".*.tmp")), "temporaries of killed writes are cleaned up"
