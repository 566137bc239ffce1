"""The sample-library comparison of `python -m trainer.scripts.baselines`, on a tiny library."""
import pytest

from trainer.paths import INSTALLED_AGENT
from trainer.scripts.baselines import sample_library_comparison


@pytest.mark.skipif(not INSTALLED_AGENT.is_file(), reason="no shipped agent")
def test_every_method_is_scored_on_each_behaviours_held_out_clips(tiny_library):
    sets, training = sample_library_comparison(INSTALLED_AGENT, tiny_library)
    assert training["epochs"] >= 1
    assert set(sets) == {"point, held-out clips (1)", "wave, held-out clips (1)"}
    for name, rows in sets.items():
        assert set(rows) == {"rlanimate", "nearest_clip", "procedural_ik"}
        for row in rows.values():
            assert row["score"] <= 100.0 and 0.0 <= row["smoothness"] <= 100.0
            assert ("label_error" in row) == name.startswith("wave") and row.get("label_error", 0.0) >= 0.0
