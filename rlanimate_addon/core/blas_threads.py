"""One BLAS thread for the agent's rollout.

numpy's OpenBLAS splits even a 64 x 320 vector-matrix product over every core. The rollout does a
few such products per frame, too small to gain from threads, and on a machine whose cores are busy
(a render, a simulation, another program) each product waits for a descheduled BLAS thread: beside
busy processes a 120-frame rollout took a median 0.9 s, against 47 ms on one thread
(docs/BENCHMARKS.md, "BLAS threads").
threadpoolctl, which the extension bundles as a wheel, caps BLAS at one thread for the rollout and
restores the user's setting afterwards. Where it is not installed, nothing is capped.
"""
from contextlib import AbstractContextManager, nullcontext
from functools import lru_cache
from typing import Protocol


class _Controller(Protocol):
    """What this module uses of threadpoolctl's ThreadpoolController (threadpoolctl ships no types)."""

    def limit(self, *, limits: int, user_api: str) -> AbstractContextManager[object]: ...


@lru_cache(maxsize=1)
def _controller() -> _Controller | None:
    """threadpoolctl's view of the loaded BLAS libraries (found once: about 10 ms), or None."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return None
    controller: _Controller = ThreadpoolController()
    return controller


def single_blas_thread() -> AbstractContextManager[object]:
    """A context manager in which numpy's BLAS uses one thread."""
    controller = _controller()
    return nullcontext() if controller is None else controller.limit(limits=1, user_api="blas")
