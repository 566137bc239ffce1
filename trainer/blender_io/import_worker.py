"""Clip import in worker processes: each clip the import cache lacks is imported by a Blender in a process of its
own, under a memory cap and a time limit, so a file that sends an importer into a spiral (a corrupt FBX whose
animation asks for a million frames, 20 GB and minutes) costs one skipped clip with a note, not the machine.

    import_into_cache(files, cache_dir, workers, limits) -> {(path, fps): RLAnimateError} of the files that failed

`workers` processes import at once, each a share of the files. A worker (`serve`: `python -c` under the bpy
module, a background Blender under Blender) caps its data segment with resource.setrlimit(RLIMIT_DATA,
`limits.memory_gb`) where the system enforces it (Linux; elsewhere the time limit alone holds), reads one
request per line on stdin, imports the clip into the cache (clip_import.import_into_cache_file) and answers
one line on stdout marked ANSWER; Blender's own prints between go where they would have gone in this
process (file descriptor 1). A worker that takes longer than `limits.seconds` over one clip, runs out of
memory or dies is ended; its clip is noted and a fresh worker takes the next one.
"""
import json
import os
import queue
import subprocess
import sys
import threading
import traceback
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from tqdm import tqdm

from rlanimate_addon.core.errors import RLAnimateError
from trainer.paths import REPO_ROOT

#: The mark of a worker's answer line on its stdout.
ANSWER = "RLANIMATE-IMPORT-ANSWER "
#: How long a worker may take to start (load Blender) before the import is refused.
START_SECONDS = 300.0


@dataclass(frozen=True)
class ImportLimits:
    """What one clip's import may take: `memory_gb` of memory (the worker's data segment) and `seconds`."""
    memory_gb: float = 2.0
    seconds: float = 60.0


def import_into_cache(files: Sequence[tuple[Path, float]], cache_dir: Path, workers: int = 1,
                      limits: ImportLimits | None = None, progress: IO | None = None) -> dict:
    """Import the clip files (path, fps) into `cache_dir` with `workers` worker processes at once; returns
    {(path, fps): RLAnimateError} of those that failed (the file's problem, or the limit it ran past). A
    progress bar goes to `progress` (None: none). RLAnimateError when a worker cannot start."""
    limits = limits or ImportLimits()
    pending = list(dict.fromkeys((Path(path), float(fps)) for path, fps in files))
    failed: dict[tuple[Path, float], RLAnimateError] = {}
    errors: list[Exception] = []
    lock = threading.Lock()
    bar = tqdm(total=len(pending), desc="importing clips", unit="clip", file=progress, disable=progress is None,
               leave=False, dynamic_ncols=True)

    def work() -> None:
        worker: _Worker | None = None
        try:
            while True:
                with lock:
                    if not pending or errors:
                        return
                    path, fps = pending.pop(0)
                worker = worker if worker is not None and worker.running else _Worker(limits)
                problem = worker.import_clip(path, fps, cache_dir)
                with lock:
                    if problem is not None:
                        failed[path, fps] = problem
                    bar.update()
        except Exception as error:  # a worker that cannot start, or a bug in the importer: the caller raises it
            with lock:
                errors.append(error)
        finally:
            if worker is not None:
                worker.close()

    threads = [threading.Thread(target=work, daemon=True) for _ in range(min(max(workers, 1), len(pending)))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    bar.close()
    if errors:
        raise errors[0]
    return failed


class _Worker:
    """One worker process and the thread that reads its answers."""

    def __init__(self, limits: ImportLimits):
        self.limits = limits
        path = os.pathsep.join(filter(None, (str(REPO_ROOT), os.environ.get("PYTHONPATH"))))
        self.process = subprocess.Popen(_command(int(limits.memory_gb * 2 ** 30)), stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, cwd=REPO_ROOT,
                                        env={**os.environ, "PYTHONPATH": path})
        assert self.process.stdin is not None and self.process.stdout is not None
        self.requests, self.replies = self.process.stdin, self.process.stdout
        self.closed = False
        self.answers: queue.Queue[dict | None] = queue.Queue()  # None: the process ended
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        try:
            ready = self.answers.get(timeout=START_SECONDS) or {}
        except queue.Empty:
            ready = {"error": f"no answer in {START_SECONDS:g} s"}
        if not ready.get("ready"):
            self.close()
            raise RLAnimateError(f"The clip importer's worker process did not start: {ready.get('error')}")

    @property
    def running(self) -> bool:
        return not self.closed and self.process.poll() is None

    def _read(self) -> None:
        for line in self.replies:
            if line.startswith(ANSWER):
                self.answers.put(json.loads(line[len(ANSWER):]))
            elif line.strip():
                os.write(1, line.encode())  # Blender's prints, where they go in this process
        self.answers.put(None)

    def import_clip(self, path: Path, fps: float, cache_dir: Path) -> RLAnimateError | None:
        """Import one clip into `cache_dir`: None when it is there, else the clip's RLAnimateError."""
        try:
            self.requests.write(json.dumps({"path": str(path), "fps": fps, "cache": str(cache_dir)}) + "\n")
            self.requests.flush()
        except OSError:  # the worker has ended: its end is read below
            pass
        try:
            answer = self.answers.get(timeout=self.limits.seconds)
        except queue.Empty:
            self.close()
            return RLAnimateError(f"{path}: importing it took longer than {self.limits.seconds:g} s, so it was "
                                  f"stopped and the clip skipped (the file may be corrupt). Re-export it, or raise "
                                  f"--import-time-limit if the clip is sound and this long.")
        if answer is None:
            ended = self.process.wait()
            self.close()
            return RLAnimateError(f"{path}: importing it ended Blender's process ({_ending(ended)}), so the clip was "
                                  f"skipped (the file may be corrupt, or need more than the {self.limits.memory_gb:g} "
                                  f"GB memory limit). Re-export it, or raise --import-memory-limit if the clip is "
                                  f"sound and this large.")
        if "memory" in answer:
            self.close()
            return RLAnimateError(f"{path}: importing it ran out of its {self.limits.memory_gb:g} GB of memory "
                                  f"(MemoryError: {answer['memory']}), so the clip was skipped (the file may be "
                                  f"corrupt). Re-export it, or raise --import-memory-limit if the clip is sound and "
                                  f"this large.")
        if "bug" in answer:
            self.close()
            raise RuntimeError(f"Importing {path} failed in its worker process:\n{answer['bug']}")
        return _problem(answer)

    def close(self) -> None:
        """End the process (its reader thread ends with it)."""
        if self.closed:
            return
        self.closed = True
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        self.reader.join()
        for stream in (self.requests, self.replies):
            try:
                stream.close()
            except OSError:  # a request it never read
                pass


def _ending(code: int) -> str:
    """How a process that ended with `code` (Popen.returncode) ended, in words."""
    return f"signal {-code}" if code < 0 else f"exit status {code}"


def _problem(answer: dict) -> RLAnimateError | None:
    """The RLAnimateError of a worker's answer, or None for a clip now in the cache."""
    from trainer.blender_io.clip_import import FrameRateMismatch
    if "frame_rate" in answer:
        return FrameRateMismatch(*answer["frame_rate"])
    return RLAnimateError(answer["problem"]) if "problem" in answer else None


def _command(memory_bytes: int) -> list[str]:
    """The worker's command line: this Python with the bpy module, or, inside Blender, Blender in the background."""
    code = f"from trainer.blender_io.import_worker import serve; serve({memory_bytes})"
    bpy = sys.modules.get("bpy")  # Blender's own Python has it loaded; the bpy module is loaded only when used
    binary = bpy.app.binary_path if bpy is not None else ""
    if binary:
        return [binary, "--background", "--factory-startup", "--python-exit-code", "1", "--python-expr", code]
    return [sys.executable, "-c", code]


def serve(memory_bytes: int) -> None:
    """The worker process: cap the memory, load Blender, then import each requested clip into the cache."""
    _cap_memory(memory_bytes)
    try:
        from trainer.blender_io import clip_import
        clip_import.rig_session.import_bpy()
    except Exception as error:
        _send({"ready": False, "error": str(error)})
        return
    _send({"ready": True})
    for line in sys.stdin:
        request = json.loads(line)
        path = Path(request["path"])
        try:
            clip_import.import_into_cache_file(path, request["fps"], Path(request["cache"]))
            _send({})
        except clip_import.FrameRateMismatch as error:
            _send({"frame_rate": [str(error.path), error.fps, error.expected]})
        except RLAnimateError as error:
            _send({"problem": str(error)})
        except MemoryError as error:
            _send({"memory": str(error) or "out of memory"})
            return  # Blender's state after a failed allocation is not to be trusted: a fresh worker goes on
        except Exception:
            _send({"bug": traceback.format_exc()})


def _cap_memory(memory_bytes: int) -> None:
    try:
        import resource
    except ImportError:  # Windows: the time limit alone holds
        return
    _, hard = resource.getrlimit(resource.RLIMIT_DATA)
    resource.setrlimit(resource.RLIMIT_DATA, (memory_bytes if hard == resource.RLIM_INFINITY
                                              else min(memory_bytes, hard), hard))


def _send(answer: dict) -> None:
    sys.stdout.write("\n" + ANSWER + json.dumps(answer) + "\n")
    sys.stdout.flush()
