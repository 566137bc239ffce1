"""The rhythm ablation on real capture as a page (docs/results/realmocap_ablation.md)."""
import math

import numpy as np

from rlanimate_addon.core.rhythm import BANDWIDTH, TEMPO_BANDWIDTH
from trainer.reporting.realmocap_report import SEED_METRICS, STYLE_METRICS, metric_cells
from trainer.reporting.tables import page, paragraphs, section, table

#: Retrieval's results: for the plain request, and for the one naming the take's tempo.
RETRIEVAL, RETRIEVAL_TEMPO = "nearest_clip", "nearest_clip, tempo asked"
#: The tempo kernel the agent files play (core/rhythm.py).
TEMPO_KERNEL = f"log {math.exp(TEMPO_BANDWIDTH):g}"
_RETRIEVAL_LABELS = {RETRIEVAL: "Nearest clip (retrieval)", RETRIEVAL_TEMPO: "Nearest clip (retrieval), tempo asked"}


def _method_label(method):
    return _RETRIEVAL_LABELS.get(method, method)


def overall_rows(results):
    """Per experiment and method: score, DTW score, median swing and frequency ratios and last-frame elevation
    error, accepted waves (realmocap_report.SEED_METRICS)."""
    rows = []
    for entry in results["experiments"].values():
        for method, summary in entry["summaries"].items():
            *cells, accepted = metric_cells(summary, SEED_METRICS)
            rows.append([f"{entry['test_set']} ({entry['test_clips']})", _method_label(method), *cells,
                         f"{accepted}/{summary['clips']}"])
    return rows


def style_rows(results, methods):
    """Per experiment, style and method of `methods` (the deterministic ones and retrieval): the per-style
    measures of realmocap_report.STYLE_METRICS."""
    rows = []
    for entry in results["experiments"].values():
        summaries = {method: entry["summaries"][method]["by_style"] for method in methods}
        for style in sorted(next(iter(summaries.values()))):
            for method, by_style in summaries.items():
                row = by_style[style]
                *cells, accepted = metric_cells(row, STYLE_METRICS)
                rows.append([entry["test_set"], style, _method_label(method), *cells, f"{accepted} / {row['takes']}"])
    return rows


#: Name prefixes of the seeded variants, each group reported as the mean over its seeds.
SEEDED = ("sampled states ", "seed ")


def _seeded(name):
    return name.startswith(SEEDED)


def findings(results):
    """Lines comparing, per test set, each deterministic setting's score / DTW score with the agent as exported,
    the seeded groups' means over their seeds, and retrieval."""
    lines = []
    for entry in results["experiments"].values():
        summaries = entry["summaries"]
        names = [name for name in summaries if name not in _RETRIEVAL_LABELS]
        base = summaries[names[0]]

        def pair(summary):
            return f"{summary['score']:.1f} / {summary['aligned_score']:.1f}"

        parts = [f"{name}: {pair(summaries[name])} ({summaries[name]['score'] - base['score']:+.1f} / "
                 f"{summaries[name]['aligned_score'] - base['aligned_score']:+.1f})"
                 for name in names[1:] if not _seeded(name)]
        for prefix in SEEDED:
            group = [summaries[name] for name in names if name.startswith(prefix)]
            parts.append(
                f"{prefix.strip()} (mean of {len(group)} seeds): "
                f"{np.mean([g['score'] for g in group]):.1f} / {np.mean([g['aligned_score'] for g in group]):.1f}"
            )
        lines.append(f"- **{entry['test_set']}** (score / DTW score): as exported {pair(base)}; " + "; ".join(parts)
                     + f"; retrieval {pair(summaries[RETRIEVAL])}; retrieval, tempo asked "
                       f"{pair(summaries[RETRIEVAL_TEMPO])}.")
    for entry in results["experiments"].values():
        checks = "; ".join(f"{rule}: {row['rate_within']:.0%} within 0.8-1.25x, median |log rate ratio| "
                           f"{row['median_log_rate_error']:.3f}, signal correlation {row['signal_correlation']:.2f}"
                           for rule, row in entry["rule_checks"].items())
        lines.append(f"- Each of the {entry['test_set']} agent's {next(iter(entry['rule_checks'].values()))['waves']} "
                     f"swinging training waves left out in turn, its rate and rhythm predicted from the rest "
                     f"(trainer/evaluation/rhythm_leave_one_out.py; no test take): {checks}.")
    for entry in results["experiments"].values():
        styles = ", ".join(f"{style} {row['phase']:+.2f} ({row['concentration']:.2f}, {row['waves']})"
                           for style, row in entry["style_phases"].items())
        lines.append(f"- The phase at which the {entry['test_set']} agent's training waves start to swing, per "
                     f"style (circular mean in radians; its concentration, 0-1; waves): {styles}; of all of them "
                     f"{entry['phase_of_all']:+.2f}.")
    return lines + [""]


#: The seeds, settings, presets and requests of the page's methods, one list item each.
_VARIANTS = (
    "- *typical tempo*: what the agent file plays for Variation Seed 0 (the panel's seed 0 is no seed): "
    f"the weighted mean rate, start and stop of the training waves near the request's exaggeration (kernel "
    f"sd {BANDWIDTH:g}) and near the typical tempo of those (the mode of their log tempos; kernel sd "
    f"{TEMPO_KERNEL}), of both arms, at their weighted circular mean phase (core/rhythm.py; the kernels "
    "and arms chosen on validation takes, docs/results/realmocap_length.md).",
    "- *mean rhythm, all waves' phase*: as files exported without their waves' phases play, and as every "
    "agent played before: the weighted mean of the waves near the exaggeration alone (kernel sd 0.05), "
    "whatever their tempo, at the circular mean phase of all training waves.",
    "- *the kernels before*: the typical tempo with the kernels of the files made before they were chosen "
    "(sd 0.05, log 1.25).",
    "- *the request's arm's waves*: the typical tempo from the training waves of the request's arm alone, "
    "as retrieval fetches only that arm's.",
    "- *sampled states N*: the typical tempo, with the stochastic states sampled (seed N) instead of their means.",
    "- *seed N*: the panel's Variation Seed N > 0: one nearby training wave's rhythm at a uniformly random "
    "phase, and sampled stochastic states.",
    "- *tempo asked*: the request names the take's own tempo (Hz, read from its swing as the trainer reads "
    "it: the panel's Tempo); the agent swings at it, its start, stop and phase those of the training "
    "waves near its exaggeration and that tempo (*mean rhythm*: of those near its exaggeration alone). "
    "Retrieval, tempo asked, ranks the training waves by exaggeration and log tempo, each in units of its sd.",
    "- *each take's own rhythm*: the agent as exported, its rhythm read from the held-out take itself (as "
    "training reads a clip's): not a method, since no request can say it, but what the agent's poses give "
    "when its rhythm is right; the gap between it and *as exported* is the rhythm's.",
    "- *preset P*: the agent trained with preset P instead, playing the typical tempo (`end_chunks` is "
    "`default` with a fifth of the "
    "update's chunks ending at the gesture's last frame, trainer/agent/buffer.py).")
#: The columns of the tables after the test set (and style): the method and realmocap_report.SEED_METRICS'.
_METRIC_COLUMNS = ["method", "score", "DTW score", "swing ratio", "frequency ratio", "last-frame elevation error (deg)",
                   "accepted"]


def ablation_markdown(results):
    """docs/results/realmocap_ablation.md from run_ablation's results."""
    deterministic = [name for name in results["variants"] if not _seeded(name)] + [RETRIEVAL, RETRIEVAL_TEMPO]
    return page(
        ["# The wave's rhythm and tempo at play time, and the training preset, on real capture (an ablation)", ""],
        paragraphs(_introduction(results)), [*_VARIANTS, ""], findings(results),
        section("All takes", "Mean score and DTW score; median swing and frequency ratios (issue 26 asks 0.75-1.33 "
                "and 0.8-1.25) and last-frame arm elevation error (degrees; asked: at most 4); waves "
                "`core.behaviour_metrics` accepts."),
        table(["test set", *_METRIC_COLUMNS], overall_rows(results)),
        section("Per style (the deterministic settings and retrieval)"),
        table(["test set", "style", *_METRIC_COLUMNS], style_rows(results, deterministic)),
        section("Hand paths", "The first right-arm test take of the worst and best styles: the wrist's side-to-side "
                "offset from its shoulder over time (left) and its path seen from the front (right), the real take "
                "in black.", "![hand paths of real takes and the variants](realmocap_ablation_paths.png)"))


def _introduction(results):
    """The page's first paragraph: the agents, how the methods answer, the command and its times."""
    timing = "; ".join(f"{entry['test_set']}: agent trained in {entry['train_seconds']:.0f} s, all variants "
                       f"scored in {entry['evaluation_cpu_seconds']:.0f} CPU s"
                       for entry in results["experiments"].values())
    return (f"One agent per test set (training seed {results['seed']}, preset `{results['preset']}`, "
            f"{results['epochs']} epochs: the agents `trainer.scripts.realmocap --epochs {results['epochs']}` "
            "trains), played with different "
            "rhythm settings and nothing retrained, beside the same seed's agents of other presets "
            "(trainer/experiments/realmocap_ablation.py). Every method answers each held-out take's own request "
            "(its auto-label and length, and where it says so the take's tempo) and is scored against it as in "
            "docs/results/realmocap.md. Regenerate: "
            f"`{results['command']}` ({timing}; one torch thread).")
