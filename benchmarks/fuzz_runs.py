"""What the fuzz benchmarks share: how long a call takes and its peak memory, and running seeds of mutations."""
import collections
import resource
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass, field


def seconds_and_peak_mb(call: Callable[[], object]) -> tuple[float, float]:
    """(seconds of one call, peak MB of a second call by tracemalloc, which sees numpy's arrays and the bytes
    Python reads), whatever the call raises: the fuzz names its outcome apart."""
    def run():
        try:
            call()
        except Exception:  # noqa: BLE001  (the outcome is the fuzz's to name)
            pass
    began = time.perf_counter()
    run()
    seconds = time.perf_counter() - began
    tracemalloc.start()
    try:
        run()
        peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
    finally:
        tracemalloc.stop()
    return seconds, peak


@dataclass
class Runs:
    """What the seeds' mutations gave: counts[kind][outcome], measures[kind] (one tuple per mutation, as the
    benchmark's fuzz appends them), failures (lines), per_seed [(seed, Counter of outcomes)], the seconds
    they took and the run's peak memory in MB."""
    counts: dict = field(default_factory=lambda: collections.defaultdict(collections.Counter))
    measures: dict = field(default_factory=lambda: collections.defaultdict(list))
    failures: list = field(default_factory=list)
    per_seed: list = field(default_factory=list)
    seconds: float = 0.0
    peak_mb: float = 0.0


def run_seeds(fuzz: Callable, seeds, mutations: int) -> Runs:
    """fuzz(seed, mutations, folder, counts, measures, failures) for each seed, in a temporary folder."""
    runs, start = Runs(), time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        for seed in seeds:
            seed_counts: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
            fuzz(seed, mutations, folder, seed_counts, runs.measures, runs.failures)
            runs.per_seed.append((seed, sum(seed_counts.values(), collections.Counter())))
            for kind, counter in seed_counts.items():
                runs.counts[kind].update(counter)
    runs.seconds = time.perf_counter() - start
    runs.peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # Linux reports kB
    return runs
