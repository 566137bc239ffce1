"""Fuzz of the agent loader: seeded mutations of the shipped agent aimed at the zip and npy headers, the
metadata, the compression (LZMA and bzip2 repacks, damaged deflate data) and the weights, with npy
header-length and entry-count bombs. Every outcome is an RLAnimateError, the original agent exactly, or
a still-valid changed file read exactly as numpy reads it; never another exception, never changed or
non-finite keys, never a load that takes seconds. (benchmarks/agent_fuzz_benchmark.py runs 3 x 3,000
and measures each load's time and memory.)"""
import collections
import time
from pathlib import Path

import numpy as np

import agent_fuzz

SHIPPED = Path(__file__).resolve().parents[2] / "rlanimate_addon" / "agents" / "default.npz"
MUTATIONS = 240
#: Far above any load (milliseconds), far below the bombs' (a 4 GiB npy header: 133 s; 1,000,000 entries:
#: 7.8 s): a bound that a shared machine cannot trip.
WORST_LOAD_SECONDS = 5.0


def test_mutated_agent_files_are_refused_or_load_exactly(tmp_path):
    reference = agent_fuzz.Reference(SHIPPED)
    generator = agent_fuzz.mutations(reference.data, np.random.default_rng(0))
    outcomes = collections.Counter()
    failures = []
    worst = 0.0
    for k in range(MUTATIONS):
        kind, data = next(generator)
        path = tmp_path / f"mutated{k}.npz"
        path.write_bytes(data)
        start = time.perf_counter()
        outcome = agent_fuzz.outcome(path, reference)
        worst = max(worst, time.perf_counter() - start)
        outcomes[kind, outcome if outcome in agent_fuzz.ACCEPTED else "failure"] += 1
        if outcome not in agent_fuzz.ACCEPTED:
            failures.append(f"mutation {k} ({kind}): {outcome}")
        path.unlink()
    assert not failures, "\n".join(failures)
    assert {kind for kind, _ in outcomes} == set(agent_fuzz.KINDS), "every kind of mutation was tried"
    assert sum(n for (_, outcome), n in outcomes.items() if outcome == "refused") > MUTATIONS // 2
    assert worst < WORST_LOAD_SECONDS
