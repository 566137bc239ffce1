"""docs/results/baselines.json and .md: RLAnimate against the baselines, one section per experiment."""
import json
from pathlib import Path

from trainer.files import atomic_write_text
from trainer.reporting.tables import markdown_table

METHOD_LABELS = {"rlanimate": "RLAnimate", "no_motion": "No motion", "class_mean": "Class mean",
                 "nearest_clip": "Nearest clip", "procedural_ik": "Procedural IK"}
METRIC_LABELS = {"score": "score", "smoothness": "smoothness", "label_error": "label error (autolabel)",
                 "forearm_angle_deg": "forearm angle at hold (deg)"}


def write_baselines_results(results_dir, section, description, sets):
    """Merge one section into results_dir/baselines.json and rewrite baselines.md from the whole file.

    sets: {set name: {method: {metric: value, ...}}}; the other sections are kept as they are, so
    the sample-library and the real-data runs each update their own.
    """
    path = Path(results_dir) / "baselines.json"
    table = json.loads(path.read_text()) if path.is_file() else {}
    table[section] = {"description": description, "sets": sets}
    atomic_write_text(path, json.dumps(table, indent=2) + "\n")
    lines = ["# RLAnimate against the baselines an animator would try first", "",
             "Nearest clip: the training clip with the closest label, time-warped to the requested length. "
             "Procedural IK: Blender's IK constraint with minimum-jerk timing (trainer/blender_io/procedural_ik.py). "
             "Each method answers the held-out clip's own request (label and length); score and smoothness "
             "as in docs/METRICS.md. Discussion: docs/REALMOCAP.md.", ""]
    for name, entry in table.items():
        lines += [f"## {name}", "", entry["description"], ""]
        for set_name, methods in entry["sets"].items():
            metric_names = [m for m in METRIC_LABELS if any(m in row for row in methods.values())]
            rows = [[METHOD_LABELS.get(method, method)]
                    + [f"{row[m]:.3g}" if m == "label_error" else f"{row[m]:.2f}" for m in metric_names]
                    for method, row in methods.items()]
            lines += [f"**{set_name}**", "", *markdown_table(["method"] + [METRIC_LABELS[m] for m in metric_names],
                                                            rows), ""]
    atomic_write_text(path.with_suffix(".md"), "\n".join(lines))
