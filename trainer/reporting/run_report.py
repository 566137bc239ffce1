"""A training run's report: report.json and report.md in the run's folder."""
import json
from pathlib import Path

from trainer.paths import shown
from trainer.reporting.behaviour_report import behaviour_words
from trainer.reporting.tables import markdown_table


def write_run_report(report, output):
    output = Path(output)
    with open(output / "report.json", "w") as handle:
        json.dump(report, handle, indent=2)
    rows = []
    for label, key in (("held-out (unseen)", "held_out"), ("training (seen)", "training")):
        if report[key] is None:  # a library without held-out clips
            rows.append([label, 0, "", "", "", "no clips with split \"test\""])
            continue
        rows.append([label, len(report[key]["clips"]), f"{report[key]['score']:.2f}",
                     f"{report[key]['smoothness']:.2f}", "", ""])
        for behaviour, entry in report[key]["by_behaviour"].items():
            count = sum(c["behaviour"] == behaviour for c in report[key]["clips"])
            rows.append([f"{label}, {behaviour}", count, f"{entry['score']:.2f}", f"{entry['smoothness']:.2f}",
                         f"{entry['aligned_score']:.2f}", behaviour_words(behaviour, entry)])
    lines = [f"# RLAnimate agent: {report['variant']}, {report['behaviour']}", "",
             f"Preset `{report['preset']}`, seed {report['seed']}, {report['epochs']} epochs (iterations of "
             f"Algorithm 1), {report['episodes']} sample episodes ({report['frames']} frames), "
             f"{report['train_seconds'] / 60:.1f} min of training (wall clock; {report['train_cpu_seconds'] / 60:.1f} "
             f"min of CPU time) with {report['torch_threads']} torch thread(s) on a machine shared with other jobs. "
             f"Clips: `{shown(report['clips']) if Path(report['clips']).exists() else report['clips']}`.", "",
             *markdown_table(["clip set", "clips", "score", "smoothness", "score, DTW", "behaviour (docs/METRICS.md)"],
                             rows), "", "Per held-out clip:", "",
             *markdown_table(["clip", "behaviour", "score", "smoothness"],
                             [[c["name"], c["behaviour"], f"{c['score']:.2f}", f"{c['smoothness']:.2f}"]
                              for c in (report["held_out"] or {"clips": []})["clips"]])]
    if report["skipped_clips"]:
        lines += ["", f"Skipped {len(report['skipped_clips'])} clip(s) of the library that did not import:", "",
                  *(f"- {problem}" for problem in report["skipped_clips"])]
    (output / "report.md").write_text("\n".join(lines) + "\n")
