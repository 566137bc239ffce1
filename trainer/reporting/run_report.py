"""A training run's report: report.json and report.md in the run's folder."""
import json
from pathlib import Path

from trainer.paths import shown
from trainer.reporting.behaviour_report import behaviour_words, clip_words
from trainer.reporting.tables import markdown_table


def write_run_report(report, output):
    output = Path(output)
    with open(output / "report.json", "w") as handle:
        json.dump(report, handle, indent=2)
    (output / "report.md").write_text("\n".join(report_lines(report)) + "\n")


def _set_rows(report):
    """Rows of the clip-set table: each set, then each behaviour in it, with how many of its clips it scores."""
    rows = []
    trained = report.get("training_clips", {})
    for label, key in (("held-out (unseen)", "held_out"), ("training (seen)", "training")):
        if report[key] is None:  # a library without held-out clips
            rows.append([label, 0, "", "", "", "no clips with split \"test\""])
            continue
        rows.append([label, len(report[key]["clips"]), f"{report[key]['score']:.2f}",
                     f"{report[key]['smoothness']:.2f}", "", ""])
        for behaviour, entry in report[key]["by_behaviour"].items():
            count = sum(c["behaviour"] == behaviour for c in report[key]["clips"])
            shown = f"{count} of {trained[behaviour]}" if key == "training" and behaviour in trained else count
            rows.append([f"{label}, {behaviour}", shown, f"{entry['score']:.2f}", f"{entry['smoothness']:.2f}",
                         f"{entry['aligned_score']:.2f}", behaviour_words(behaviour, entry)])
    return rows


def report_lines(report):
    """The lines of report.md."""
    held_out = (report["held_out"] or {"clips": []})["clips"]
    lines = [f"# RLAnimate agent: {report['variant']}, {report['behaviour']}", "",
             f"Preset `{report['preset']}`, seed {report['seed']}, {report['epochs']} epochs (iterations of "
             f"Algorithm 1), {report['episodes']} sample episodes ({report['frames']} frames), "
             f"{report['train_seconds'] / 60:.1f} min of training (wall clock; {report['train_cpu_seconds'] / 60:.1f} "
             f"min of CPU time) with {report['torch_threads']} torch thread(s) on a machine shared with other jobs. "
             f"Clips: `{shown(report['clips']) if Path(report['clips']).exists() else report['clips']}`.", "",
             *markdown_table(["clip set", "clips", "score", "smoothness", "score, DTW", "behaviour (docs/METRICS.md)"],
                             _set_rows(report)), "",
             f"Every held-out clip of a trained behaviour is scored ({len(held_out)}). The training (seen) set is "
             f"the paper's {len(report['training']['clips'])} training clips, shared between the behaviours and "
             "spread evenly over each one's clips (a behaviour's \"k of n\": k of its n training clips).", "",
             "Per held-out clip:", "",
             *markdown_table(["clip", "behaviour", "score", "score, DTW", "smoothness", "measures"],
                             [[c["name"], c["behaviour"], f"{c['score']:.2f}", f"{c['aligned_score']:.2f}",
                               f"{c['smoothness']:.2f}", clip_words(c)] for c in held_out])]
    if report.get("not_scored"):
        lines += ["", f"Not scored: {len(report['not_scored'])} held-out clip(s):", "",
                  *(f"- {entry['name']}: {entry['why']}" for entry in report["not_scored"])]
    if report["skipped_clips"]:
        lines += ["", f"Skipped {len(report['skipped_clips'])} clip(s) of the library that did not import:", "",
                  *(f"- {problem}" for problem in report["skipped_clips"])]
    return lines
