"""Fuzz of clip manifests through the importer: seeded mutations (wrong types at every field, entries that are
not objects, a wrong top level, deep nesting, damaged bytes) of a 4-clip library of the sample's clips,
each loaded by clip_import.import_clip_directory as training loads it. Every outcome is a refusal naming
the manifest, entries skipped with a note naming the manifest and the entry, or clips whose labels make a
finite objective; never a traceback. (benchmarks/manifest_fuzz_benchmark.py runs 1,000 per seed.)"""
import collections
import sys
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "motion"))
import manifest_fuzz  # noqa: E402  (tests/trainer/motion/manifest_fuzz.py)
from trainer.blender_io import clip_import  # noqa: E402

MUTATIONS = 300


def test_mutated_manifests_are_refused_or_skip_entries_with_a_note(tmp_path):
    manifest = manifest_fuzz.small_library(tmp_path)
    clips, problems = clip_import.import_clip_directory(tmp_path / "manifest.json")  # imported once, then cached
    assert len(clips) == 4 and problems == []
    generator = manifest_fuzz.mutations(manifest, np.random.default_rng(0))
    path = tmp_path / "manifest.json"
    outcomes, failures = collections.Counter(), []
    for k in range(MUTATIONS):
        kind, data = next(generator)
        path.write_bytes(data)
        outcome = manifest_fuzz.outcome(path, clip_import.import_clip_directory)
        outcomes[outcome if outcome in manifest_fuzz.ACCEPTED else "failure"] += 1
        if outcome not in manifest_fuzz.ACCEPTED:
            failures.append(f"mutation {k} ({kind}): {outcome}")
    assert failures == []
    assert outcomes["refused"] >= 10 and outcomes["skipped"] >= 50, outcomes  # the fuzz reaches both paths
