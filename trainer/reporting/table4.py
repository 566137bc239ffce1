"""docs/results/table4.md: RLAnimate, its ablations and the baselines, methods as rows, mean ± sd over seeds."""
from trainer.reporting.baselines_report import METHOD_LABELS as BASELINE_LABELS
from trainer.reporting.plots import COLUMN_LABELS, VARIANT_LABELS
from trainer.reporting.tables import markdown_table

LABELS = {**VARIANT_LABELS, **BASELINE_LABELS, "rlanimate": "RLAnimate"}
SHARED = (("score", "score", 2), ("aligned_score", "score, DTW", 2), ("smoothness", "smoothness", 2))
WAVE_FIELDS = (("swing_ratio_median", "swing ratio", 2), ("frequency_ratio_median", "frequency ratio", 2),
               ("cycles_min", "full cycles (min)", 1), ("accepted_share", "waves accepted (share)", 2))
POINT_FIELDS = (("pointing_angle_median", "own aim (deg, median)", 1), ("pointing_angle_max", "own aim (deg, max)", 1))
#: The rows of each behaviour key, with the fields of its own measures.
OWN_FIELDS = {"wave": WAVE_FIELDS, "point": POINT_FIELDS}
ELEVATION = (("elevation_first_error_max", "elevation error, first frame (deg, max)", 1),
             ("elevation_last_error_max", "last frame", 1))
SPLITS = {"held-out": "Held-out requests of the sample library (the paper's test set)",
          "harder": "Harder split: targets outside the training ranges, new wave styles, 0.5x-1.5x lengths "
                    "(trainer/evaluation/harder_split.py)"}


def cell(value, digits):
    """'mean ± sd' over seeds, or the value alone for one seed (or a deterministic baseline)."""
    if value["mean"] is None:
        return "n/a"
    mean = f"{value['mean']:.{digits}f}"
    return f"{mean} ± {value['sd']:.{digits}f}" if value["n"] > 1 else mean


def table4_markdown(report):
    lines = ["# Table 4: RLAnimate, its ablations and the baselines", "", report["settings"], "",
             "Each method answers the split's requests (label and length); behaviour metrics as in docs/METRICS.md "
             "(per seed: scores are means over the requests, behaviour measures medians or extremes; here the mean "
             "± sd of those over the seeds that finished, n = seeds). Baselines are deterministic: one value. An "
             "agent trained on one behaviour is asked for that behaviour only.", ""]
    for split, columns in report["table"].items():
        lines += [f"## {SPLITS.get(split, split)}", ""]
        for column, methods in columns.items():
            for behaviour, own in OWN_FIELDS.items():
                rows = {m: entry[behaviour] for m, entry in methods.items() if behaviour in entry}
                if not rows:
                    continue
                fields = SHARED + own + ELEVATION
                count = next(iter(rows.values()))["requests"]["mean"]
                lines += [f"### {COLUMN_LABELS[column]} agents: {behaviour} requests ({count:.0f})", ""]
                lines += markdown_table(("method", "n") + tuple(title for _, title, _ in fields),
                                        [[LABELS.get(m, m), str(entry["score"]["n"])]
                                         + [cell(entry[key], digits) for key, _, digits in fields]
                                         for m, entry in rows.items()])
                lines.append("")
    if report.get("random_targets"):
        count = report["random_target_count"]
        lines += [f"## Own aim at {count} random unseen targets per arm", "",
                  "Each pointing agent, no aim correction, at the class-average length; targets drawn over the "
                  "library's ranges (trainer/evaluation/behaviour.py, the same targets for every agent). Degrees at "
                  f"the hold, the median and the worst of the {count} per arm; issue 10 asks at most 3 and 8.", ""]
        for column, variants in report["random_targets"].items():
            lines += [f"### {COLUMN_LABELS[column]} agents", ""]
            lines += markdown_table(
                ("method", "n", "left: median", "left: max", "right: median", "right: max"),
                [
                    [LABELS.get(v, v), str(entry["left"]["median"]["n"])]
                    + [cell(entry[arm][key], 1) for arm in ("left", "right") for key in ("median", "max")]
                    for v, entry in variants.items()
                ],
            )
            lines.append("")
    lines += ["## Training runs", ""]
    lines += markdown_table(
        ("variant", "column", "seed", "episodes", "wall s", "CPU s", "held-out score", "seen score"),
        [
            [
                LABELS.get(r["variant"], r["variant"]),
                r["column"],
                r["seed"],
                r["episodes"],
                f"{r['train_seconds']:.0f}",
                f"{r['train_cpu_seconds']:.0f}",
                f"{r['held_out_score']:.2f}",
                f"{r['seen_score']:.2f}",
            ]
            for r in report["training"].values()
        ],
    )
    return "\n".join(lines) + "\n"
