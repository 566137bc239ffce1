"""How well the rhythm model's play-time rule predicts a training wave it was not fitted on (numpy).

Each training wave is left out in turn; the model fitted on the rest draws the rhythm for the left-out wave's
exaggeration (seed None, as the panel's Variation Seed 0 plays it), which is compared with the wave's own:
whether the rate is within the frequency ratio's tolerance (0.8-1.25x), the median |log rate ratio|, and the
correlation of the two rhythms' signals over the wave's frames (core/rhythm.py; 1 when they swing in step,
0 when unrelated). It needs no test take: the rule can be chosen on it before any test is scored.
"""
import numpy as np

from rlanimate_addon.core import rhythm

#: The frequency ratios counted as the same rate (issue 26's per-style bar).
RATE_TOLERANCE = (0.8, 1.25)


def leave_one_out(exaggerations, rhythms, frame_counts, typical_tempo, tempo_bandwidth=None, arms=None,
                  bandwidth=None, by_arm=None):
    """{'waves', 'rate_within', 'median_log_rate_error', 'signal_correlation'} over the (K,) training waves'
    exaggerations, Rhythms and frame counts and arms (K; None: not known), for the model with `typical_tempo` on
    or off, its tempo kernel's sd in log Hz, exaggeration kernel's sd and `by_arm` (None: rhythm's defaults)."""
    exaggerations = np.asarray(exaggerations, dtype=np.float64)
    within, log_errors, correlations = [], [], []
    for left_out, (own, frames) in enumerate(zip(rhythms, frame_counts, strict=True)):
        keep = [k for k in range(len(rhythms)) if k != left_out]
        model = rhythm.RhythmModel.fit(exaggerations[keep], [rhythms[k] for k in keep],
                                       None if arms is None else [arms[k] for k in keep])
        drawn = model.with_settings(bandwidth, typical_tempo, tempo_bandwidth, by_arm).draw(
            exaggerations[left_out], arm=None if arms is None else arms[left_out])
        ratio = drawn.frequency / own.frequency
        within.append(RATE_TOLERANCE[0] <= ratio <= RATE_TOLERANCE[1])
        log_errors.append(abs(np.log(ratio)))
        a, b = rhythm.signals(drawn, frames), rhythm.signals(own, frames)  # (N, 2) each
        correlations.append(float(np.sum(a * b) / max(np.sqrt(np.sum(a * a) * np.sum(b * b)), 1e-12)))
    return {"waves": len(rhythms), "rate_within": float(np.mean(within)),
            "median_log_rate_error": float(np.median(log_errors)), "signal_correlation": float(np.mean(correlations))}


def swinging_check(read, typical_tempo, tempo_bandwidth=None, by_arm=None, bandwidth=None):
    """leave_one_out over the training waves that swing (`read`: wave_rhythm.swinging's (clip, Rhythm) pairs),
    each predicted from its own arm's (`by_arm`) or both arms'."""
    return leave_one_out([float(np.ravel(clip.attributes)[0]) for clip, _ in read], [r for _, r in read],
                         [len(clip.rotvecs) for clip, _ in read], typical_tempo, tempo_bandwidth,
                         [clip.arm for clip, _ in read], bandwidth, by_arm)
