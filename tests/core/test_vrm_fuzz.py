"""Fuzz of the VRM reader: seeded mutations of the real VRM 0.x robot's header and JSON chunk (bytes,
text, values, the humanoid map, nesting, size). Every outcome is an RLAnimateError, the original map,
or a changed map read exactly as the changed JSON says; never another exception, never a read that
takes seconds. (benchmarks/vrm_fuzz_benchmark.py runs at least 1,000 and measures each read's time and
memory.)"""
import collections
import time
from pathlib import Path

import numpy as np
import pytest

import vrm_fuzz

ROBOT = Path(__file__).resolve().parents[3] / "shared" / "rigs" / "vrm" / "unavi_robot_vrm0.vrm"
MUTATIONS = 160
#: Far above any read (milliseconds), far below the 6-12 s a 32 MB chunk took before it was capped.
WORST_READ_SECONDS = 3.0


def test_mutated_vrm_files_are_refused_or_read_as_their_json_says(tmp_path):
    if not ROBOT.is_file():
        pytest.skip(f"{ROBOT} is absent: the VRM fuzz reads ../shared/rigs (see its README.md)")
    reference = vrm_fuzz.Reference(ROBOT)
    generator = vrm_fuzz.mutations(reference.data, np.random.default_rng(0))
    outcomes, failures, worst = collections.Counter(), [], 0.0
    for k in range(MUTATIONS):
        kind, data = next(generator)
        path = tmp_path / f"mutated{k}.vrm"
        path.write_bytes(data)
        start = time.perf_counter()
        outcome = vrm_fuzz.outcome(path, reference)
        worst = max(worst, time.perf_counter() - start)
        outcomes[kind, outcome if outcome in vrm_fuzz.ACCEPTED else "failure"] += 1
        if outcome not in vrm_fuzz.ACCEPTED:
            failures.append(f"mutation {k} ({kind}): {outcome}")
        path.unlink()
    assert not failures, "\n".join(failures)
    assert {kind for kind, _ in outcomes} == set(vrm_fuzz.KINDS), "every kind of mutation was tried"
    refused = sum(n for (_, outcome), n in outcomes.items() if outcome == "refused")
    assert MUTATIONS // 3 < refused < MUTATIONS, "most mutations are refused, and some still read"
    assert worst < WORST_READ_SECONDS
