"""PNG plots of training runs: loss and score curves, Figure 3, length flexibility, and hand paths (matplotlib, Agg)."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

VARIANT_LABELS = {"rlanimate": "RLAnimate", "single_state": "single state",
                 "single_dynamics": "single dynamics space", "supervised": "supervised loss"}
COLUMN_LABELS = {"wave": "Wave", "point": "Point", "both": "Wave and Point"}


def _series(history, key):
    points = [(entry["epoch"], entry[key]) for entry in history if key in entry]
    return [p[0] for p in points], [p[1] for p in points]


def training_curves(history, path, title=""):
    """Losses (log scale) and seen/unseen score over epochs of one run's history."""
    figure, (losses, scores) = plt.subplots(1, 2, figsize=(11, 4))
    for key in sorted({k for entry in history for k in entry if k.startswith("loss/")}):
        epochs, values = _series(history, key)
        losses.plot(epochs, values, label=key[5:])
    losses.set_yscale("symlog", linthresh=1e-3)  # some terms (the Beta NLL) go negative
    losses.set_xlabel("epoch")
    losses.set_title("losses (mean over the epoch's update steps)")
    losses.legend(fontsize=8)
    for split, style in (("seen", "-o"), ("unseen", "-s")):
        epochs, values = _series(history, f"{split}/score")
        scores.plot(epochs, values, style, markersize=3, label=f"{split} clips")
    if scores.lines:
        scores.set_ylim(0, 100.5)
    scores.set_xlabel("epoch")
    scores.set_ylabel("score")
    scores.set_title("score (deterministic rollouts)")
    scores.legend(fontsize=8)
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def figure3(histories, path, split):
    """The paper's Figure 3 row for `split` ('seen' or 'unseen'): score over epochs, one panel per
    column (wave, point, both), one line per variant. `histories[variant][column]` is a run's history."""
    figure, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    for axis, column in zip(axes, COLUMN_LABELS, strict=True):
        for variant, label in VARIANT_LABELS.items():
            history = histories.get(variant, {}).get(column)
            if history:
                epochs, values = _series(history, f"{split}/score")
                axis.plot(epochs, values, "-o", markersize=3, label=label)
        axis.set_title(COLUMN_LABELS[column])
        axis.set_xlabel("epoch")
        axis.set_ylabel("score")
        if axis.lines:
            axis.set_ylim(0, 100.5)  # early scores can be far below 0 (the log penalty); 0-100 shows the race
            axis.legend(fontsize=8)
    which = "clips from the training set" if split == "seen" else "clips excluded from the training set"
    figure.suptitle(f"Imitating {which}")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def length_flexibility(results, path, threshold):
    """Smoothness against the time scale of the gesture, one line per behaviour, with the threshold."""
    figure, axis = plt.subplots(figsize=(6, 4))
    for behaviour, by_scale in results.items():
        scales = sorted(by_scale, key=float)
        axis.plot([float(s) for s in scales], [by_scale[s] for s in scales], "-o", label=behaviour)
    axis.axhline(threshold, color="grey", linestyle="--", label=f"visible artefacts ({threshold})")
    axis.set_xlabel("length / class average length")
    axis.set_ylabel("smoothness")
    axis.set_title("Length flexibility (held-out clips)")
    axis.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def wave_hand_paths(panels, path):
    """Generated against reference hand paths of waves, one row per request: the wrist's side-to-side
    position relative to its shoulder over time, and its path in the frontal plane.

    panels: [(title, arm, {label: (F, 10, 3) description-joint positions})], the reference first."""
    from rlanimate_addon.core import behaviour_metrics as bm

    figure, axes = plt.subplots(len(panels), 2, figsize=(11, 2.6 * len(panels)), squeeze=False)
    for (title, arm, clips), (over_time, frontal) in zip(panels, axes, strict=True):
        for k, (label, positions) in enumerate(clips.items()):
            wrist = bm.joint(positions, f"{arm.lower()}_wrist")
            shoulder = bm.joint(positions, f"{arm.lower()}_shoulder")
            style = {"color": "black", "linewidth": 2.0} if k == 0 else {"linewidth": 1.2}
            over_time.plot(100 * (wrist[:, 0] - shoulder[:, 0]), label=label, **style)
            frontal.plot(
                100 * (wrist[:, 0] - shoulder[:, 0]), 100 * (wrist[:, 2] - shoulder[:, 2]), label=label, **style
            )
            run = bm.hand_up_run(positions, arm)
            if k == 0 and run is not None:
                over_time.axvspan(run[0], run[1], color="0.9", zorder=0)
        over_time.set_title(f"{title}: wrist side to side (grey: reference hand up)", fontsize=9)
        over_time.set_xlabel("frame")
        over_time.set_ylabel("cm from shoulder")
        _front_view(frontal, title)
        over_time.legend(fontsize=7, loc="upper left")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)


def _front_view(axis, title):
    """Titles and scales a wrist path seen from the front, in cm at equal scale."""
    axis.set_title(f"{title}: wrist path, front view", fontsize=9)
    axis.set_xlabel("side (cm)")
    axis.set_ylabel("up (cm)")
    axis.set_aspect("equal", adjustable="datalim")


def gesture_hand_paths(panels, path):
    """Generated against reference hand paths of held gestures (guide, raise hand), one row per request:
    the wrist's height above its shoulder over time, its path seen from above (with the line to the
    target, when there is one) and from the front.

    panels: [(title, arm, {label: (F, 10, 3) description-joint positions}, target (3,) or None)], the
    reference first."""
    from rlanimate_addon.core import behaviour_metrics as bm

    figure, axes = plt.subplots(len(panels), 3, figsize=(14, 3.0 * len(panels)), squeeze=False)
    for (title, arm, clips, target), (over_time, above, frontal) in zip(panels, axes, strict=True):
        for k, (label, positions) in enumerate(clips.items()):
            relative = 100 * (
                bm.joint(positions, f"{arm.lower()}_wrist") - bm.joint(positions, f"{arm.lower()}_shoulder")
            )
            style = {"color": "black", "linewidth": 2.0} if k == 0 else {"linewidth": 1.2}
            over_time.plot(relative[:, 2], label=label, **style)
            above.plot(relative[:, 0], -relative[:, 1], label=label, **style)
            frontal.plot(relative[:, 0], relative[:, 2], label=label, **style)
            if k == 0 and target is not None:
                shoulder = bm.joint(positions, f"{arm.lower()}_shoulder")[0]
                way = np.asarray(target)[:2] - shoulder[:2]
                way = 80 * way / np.linalg.norm(way)
                above.plot([0, way[0]], [0, -way[1]], ":", color="green", label="to the target")
        over_time.set_title(f"{title}: wrist height above the shoulder", fontsize=9)
        over_time.set_xlabel("frame")
        over_time.set_ylabel("cm")
        above.set_title(f"{title}: wrist path from above", fontsize=9)
        above.set_xlabel("side (cm, + character's left)")
        above.set_ylabel("forward (cm)")
        _front_view(frontal, title)
        above.set_aspect("equal", adjustable="datalim")
        over_time.legend(fontsize=7, loc="upper left")
        above.legend(fontsize=7, loc="best")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
