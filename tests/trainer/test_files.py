"""The atomic write: synced file and folder, and the temporaries of killed writers removed."""
import os
import subprocess
import sys

from trainer import files
from trainer.paths import REPO_ROOT


def _dead_pid():
    """The id of a process that has exited."""
    process = subprocess.Popen([sys.executable, "-c", "pass"])
    process.wait()
    return process.pid


def test_temporaries_of_killed_writers_are_removed_and_a_running_writers_kept(tmp_path):
    target = tmp_path / "checkpoint.pt"
    stale = [tmp_path / f".checkpoint.pt.{_dead_pid()}.tmp" for _ in range(3)]
    for path in stale:
        path.write_bytes(bytes(1000))  # a checkpoint write killed half way
    running = tmp_path / f".checkpoint.pt.{os.getppid()}.tmp"  # a live process still writing
    running.write_bytes(b"in progress")
    other = tmp_path / ".agent.npz.1.tmp"  # another file's temporary: not ours to judge
    other.write_bytes(b"x")
    with files.atomic_open(target) as handle:
        handle.write(b"new checkpoint")
    assert target.read_bytes() == b"new checkpoint"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([target.name, running.name, other.name])


def test_the_file_and_its_folder_are_synced(tmp_path, monkeypatch):
    synced = []
    real_fsync = os.fsync

    def recording_fsync(descriptor):
        synced.append(os.path.realpath(f"/proc/self/fd/{descriptor}") if os.path.isdir("/proc/self/fd")
                      else descriptor)
        real_fsync(descriptor)

    monkeypatch.setattr(os, "fsync", recording_fsync)
    files.atomic_write_text(tmp_path / "cache" / "entry.txt", "data")
    assert len(synced) == 2
    if os.path.isdir("/proc/self/fd"):
        assert synced[0].endswith(".tmp") and synced[1] == str((tmp_path / "cache").resolve())


def test_writes_killed_half_way_do_not_pile_up(tmp_path):
    """Real writers killed with SIGKILL mid-write, as a killed training run is: each write removes the
    temporaries of the killed ones before it, and a finished write leaves only the file."""
    target = tmp_path / "checkpoint.pt"
    writer = ("import sys, time\nfrom trainer import files\n"
              "with files.atomic_open(sys.argv[1]) as handle:\n"
              "    handle.write(bytes(1 << 20)); handle.flush(); print('writing', flush=True); time.sleep(60)\n")
    for _ in range(3):
        process = subprocess.Popen([sys.executable, "-c", writer, str(target)], stdout=subprocess.PIPE, text=True,
                                   cwd=REPO_ROOT)
        assert process.stdout.readline().strip() == "writing"
        process.kill()
        process.wait()
        process.stdout.close()
        left = list(tmp_path.glob(".checkpoint.pt.*.tmp"))
        assert [p.name for p in left] == [f".checkpoint.pt.{process.pid}.tmp"], "only the last killed write's"
    with files.atomic_open(target) as handle:
        handle.write(b"whole")
    assert [p.name for p in tmp_path.iterdir()] == ["checkpoint.pt"] and target.read_bytes() == b"whole"
