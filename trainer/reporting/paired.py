"""Two methods compared on the same takes: the mean of their per-take differences and its 95% interval.

Each take is answered by both methods, so their scores on it are paired; the gap's interval is the t interval
of the per-take differences (scipy.stats.t), which a mean over seeds of one method's per-take scores keeps.
"""
from collections.abc import Sequence

import numpy as np
from scipy import stats

#: The interval's coverage.
CONFIDENCE = 0.95


def paired_gap(ours: Sequence[float], theirs: Sequence[float]) -> dict[str, float]:
    """{'mean', 'low', 'high', 'takes'}: the mean of ours - theirs over the takes and its CONFIDENCE t interval
    (low = high = mean for a single take)."""
    differences = np.asarray(ours, dtype=np.float64) - np.asarray(theirs, dtype=np.float64)
    mean = float(differences.mean())
    if len(differences) < 2:
        return {"mean": mean, "low": mean, "high": mean, "takes": len(differences)}
    half = float(stats.t.ppf(0.5 + CONFIDENCE / 2, len(differences) - 1) * stats.sem(differences))
    return {"mean": mean, "low": mean - half, "high": mean + half, "takes": len(differences)}


def gap_cell(gap: dict[str, float]) -> str:
    """'-3.6 (-7.6 to +0.4)'."""
    return f"{gap['mean']:+.1f} ({gap['low']:+.1f} to {gap['high']:+.1f})"
