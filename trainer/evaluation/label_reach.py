"""What tempo a wave's label can reach on a test: a bound on every rhythm taken from the label (numpy).

The paper's wave request names an exaggeration, not a tempo. A rule that takes a wave's rhythm from the training
waves near its exaggeration (core/rhythm.py, as the agent plays; nearest-clip retrieval fetches one of them) can
only play a rate those waves swing at. For each test style this reads its labels and median tempo; how many
training waves lie within each of NEIGHBOURHOODS of those labels, and how many of them swing within the frequency
ratio's tolerance of that tempo (and of which styles they are); and the median rate ratio over the style's waves
that each rhythm rule of the kernels below plays. No agent is needed and nothing is chosen from it: it is a
diagnosis of the test, not a method.
"""
import math

import numpy as np

from rlanimate_addon.core.errors import RLAnimateError
from trainer.evaluation.rhythm_leave_one_out import RATE_TOLERANCE
from trainer.motion import wave_rhythm

#: Exaggeration: half-widths of the label neighbourhoods counted.
NEIGHBOURHOODS = (0.05, 0.1, 0.2)
#: The rules played: the exaggeration kernel's sd; the tempo kernel as a rate factor (its log is the sd in log
#: Hz; None: the mean rhythm of the nearby waves, whatever their tempo); a request's own arm's waves or both arms'.
EXAGGERATION_KERNELS = (0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 1.0)
TEMPO_KERNELS = (None, 1.05, 1.25, 2.0)
BY_ARM = (False, True)


def label_reach(train_read, test_read) -> dict:
    """{styles: {style: {takes, labels (lowest, highest), tempo_hz, near {half-width: {waves, styles, in_reach,
    in_reach_styles}}, rules {in_band, lowest, highest}}}, rules, in_band_in_every_style} over the test waves
    `test_read` by style.

    `train_read`: the training waves that swing (wave_rhythm.swinging's (clip, Rhythm) pairs, of one frame
    rate), whose RhythmModel the rules play; `test_read`: the test waves that swing, likewise. A style's `rules`:
    of the rules' medians (over its waves) of the rate played over the wave's own, how many lie within
    RATE_TOLERANCE, and the lowest and highest; `in_band_in_every_style`: the rules whose median does so in every
    style."""
    rates = {clip.fps for clip, _ in train_read}
    if len(rates) != 1:
        raise RLAnimateError(f"The training waves have frame rates {sorted(rates)}: bring them to one frame rate "
                             f"before reading what their labels reach.")
    fps = rates.pop()
    train = [(_label(clip), read.frequency * clip.fps, clip.style) for clip, read in train_read]
    model = wave_rhythm.rhythm_model(train_read)
    rules = [model.with_settings(bandwidth=sd, typical_tempo=tempo is not None, by_arm=by_arm,
                                 tempo_bandwidth=None if tempo is None else math.log(tempo))
             for sd in EXAGGERATION_KERNELS for tempo in TEMPO_KERNELS for by_arm in BY_ARM]
    table, in_band = {}, np.ones(len(rules), dtype=bool)
    for style in sorted({clip.style for clip, _ in test_read}):
        waves = [(clip, read) for clip, read in test_read if clip.style == style]
        labels = np.array([_label(clip) for clip, _ in waves])
        tempos = np.array([read.frequency * clip.fps for clip, read in waves])  # Hz
        tempo = float(np.median(tempos))
        near = {}
        for width in NEIGHBOURHOODS:
            nearby = [(hz, name) for e, hz, name in train if labels.min() - width <= e <= labels.max() + width]
            in_reach = [name for hz, name in nearby if RATE_TOLERANCE[0] <= hz / tempo <= RATE_TOLERANCE[1]]
            near[str(width)] = {"waves": len(nearby), "styles": sorted({name for _, name in nearby}),
                                "in_reach": len(in_reach), "in_reach_styles": sorted(set(in_reach))}
        medians = np.array(
            [
                np.median(
                    [
                        rule.draw(_label(clip), arm=clip.arm).frequency * fps / hz
                        for (clip, _), hz in zip(waves, tempos, strict=True)
                    ]
                )
                for rule in rules
            ]
        )  # (rules,)
        within = (medians >= RATE_TOLERANCE[0]) & (medians <= RATE_TOLERANCE[1])
        in_band &= within
        table[style] = {"takes": len(waves), "labels": (float(labels.min()), float(labels.max())), "tempo_hz": tempo,
                        "near": near, "rules": {"in_band": int(within.sum()), "lowest": float(medians.min()),
                                                "highest": float(medians.max())}}
    return {"styles": table, "rules": len(rules), "in_band_in_every_style": int(in_band.sum())}


def _label(clip):
    return float(np.ravel(clip.attributes)[0])
