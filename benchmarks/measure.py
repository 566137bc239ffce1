"""How long a call takes and how much memory it holds at its peak, for the fuzz benchmarks."""
import time
import tracemalloc
from collections.abc import Callable


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
