"""Fuzz of the agent loader: seeded mutations of the shipped agent aimed at the zip and npy headers and
the metadata. Every outcome is an RLAnimateError, the original agent exactly, or a still-valid changed
file read exactly as numpy reads it; never another exception, never changed or non-finite keys.
(benchmarks/agent_fuzz_benchmark.py runs 3,000.)"""
import collections
import time
from pathlib import Path

import numpy as np

import agent_fuzz

SHIPPED = Path(__file__).resolve().parents[2] / "rlanimate_addon" / "agents" / "default.npz"
MUTATIONS = 240


def test_mutated_agent_files_are_refused_or_load_exactly(tmp_path):
    reference = agent_fuzz.Reference(SHIPPED)
    generator = agent_fuzz.mutations(reference.data, np.random.default_rng(0))
    outcomes = collections.Counter()
    failures = []
    start = time.perf_counter()
    for k in range(MUTATIONS):
        kind, data = next(generator)
        path = tmp_path / f"mutated{k}.npz"
        path.write_bytes(data)
        outcome = agent_fuzz.outcome(path, reference)
        outcomes[kind, outcome if outcome in agent_fuzz.ACCEPTED else "failure"] += 1
        if outcome not in agent_fuzz.ACCEPTED:
            failures.append(f"mutation {k} ({kind}): {outcome}")
        path.unlink()
    assert not failures, "\n".join(failures)
    assert {kind for kind, _ in outcomes} == set(agent_fuzz.KINDS), "every kind of mutation was tried"
    assert sum(n for (_, outcome), n in outcomes.items() if outcome == "refused") > MUTATIONS // 2
    assert time.perf_counter() - start < 20.0
