"""The model search on real capture's validation takes as a page (docs/results/realmocap_model.md)."""
import numpy as np

from trainer.reporting.realmocap_report import over_seeds
from trainer.reporting.tables import markdown_table

_REQUESTS = {"paper": "label only (the paper's)", "_tempo": "tempo asked"}
#: The search table's columns: (key of validation_summary, decimals).
MODEL_METRICS = (("score", 1), ("aligned_score", 1), ("smoothness_min", 2), ("rough_takes", 0),
                 ("worst_style_last_error", 1))


def _cells(summaries):
    """Cells of MODEL_METRICS over one preset's seeds (mean ± sd when several)."""
    return [over_seeds([s[key] for s in summaries], digits) for key, digits in MODEL_METRICS]


def model_rows(results):
    """Per validation set, request and preset: the measures of MODEL_METRICS and the training CPU time; retrieval
    last."""
    rows = []
    for entry in results["experiments"].values():
        label = f"{entry['validates']} ({entry['validation_clips']})"
        for request, request_label in _REQUESTS.items():
            for preset, by_seed in entry["presets"].items():
                cpu = np.mean([scored["train_cpu_seconds"] for scored in by_seed.values()])
                rows.append([label, request_label, f"`{preset}` ({len(by_seed)} seed{'s' * (len(by_seed) > 1)})",
                             *_cells([scored[request] for scored in by_seed.values()]), f"{cpu:.0f}"])
            rows.append([label, request_label, "Nearest clip", *_cells([entry["retrieval"][request]]), ""])
    return rows


def style_rows(results, request="_tempo"):
    """Per validation set and style: each preset's DTW score (mean over seeds) and retrieval's, for `request`."""
    rows = []
    for entry in results["experiments"].values():
        styles = sorted(entry["retrieval"][request]["by_style"])
        for style in styles:
            cells = [f"{np.mean([s[request]['by_style'][style]['aligned_score'] for s in by_seed.values()]):.1f}"
                     for by_seed in entry["presets"].values()]
            rows.append([entry["validates"], style, *cells,
                         f"{entry['retrieval'][request]['by_style'][style]['aligned_score']:.1f}"])
    return rows


def model_markdown(results):
    """docs/results/realmocap_model.md from run_models's results."""
    presets = list(next(iter(results["experiments"].values()))["presets"])
    return "\n".join([
        "# Real capture: the model and training search on validation takes", "",
        f"Each preset trained {results['epochs']} epochs, seeds {', '.join(map(str, results['seeds']))}, on the "
        "validation experiments' training takes (no test take), and scored through its exported agent on the "
        "validation takes, asked with the label alone and with each take's tempo, beside nearest-clip retrieval "
        f"from the same takes. Regenerate: `{results['command']}`.", "",
        "Least smoothness and rough takes: over the validation takes, the artefact threshold being 98.5; last-frame "
        "error: the largest of the styles' median last-frame arm elevation errors (degrees; the bar is 4).", "",
        *markdown_table(["validation set", "request", "method", "score", "DTW score", "least smoothness",
                         "takes under 98.5", "worst style's last-frame error (deg)", "training CPU s"],
                        model_rows(results)),
        "", "## DTW score per style, tempo asked", "",
        *markdown_table(["validation set", "style", *(f"`{p}`" for p in presets), "Nearest clip"],
                        style_rows(results)), ""])
