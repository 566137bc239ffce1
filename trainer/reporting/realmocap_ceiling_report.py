"""The real-capture agents' ceiling as a page (docs/results/realmocap_ceiling.md): the wave agents asked for takes
they were trained on beside retrieval that may not return the take, and for the test takes."""
import numpy as np

from trainer.reporting.paired import gap_cell
from trainer.reporting.realmocap_report import REQUEST_LABELS, over_seeds
from trainer.reporting.tables import markdown_table

#: What the page calls each set and request of run_ceiling's results.
SETS = {"trained": "takes 007-008, trained on (retrieval: the other takes)",
        "test": "takes 009-010, never seen (retrieval: every training take)"}


def ceiling_rows(results):
    """Per set and request: the agents' score, DTW score, takes under 98.5 and worst style's last-frame error
    (mean ± sd over the seeds), retrieval's, and the paired score and DTW gaps."""
    rows = []
    for set_name, set_label in SETS.items():
        for suffix, request_label in REQUEST_LABELS.items():
            entry = results["sets"][set_name + suffix]
            agents, retrieval = list(entry["agents"].values()), entry["retrieval"]

            def agent_cell(key, digits, agents=agents):
                return over_seeds([a[key] for a in agents], digits)
            rows.append([f"{set_label} ({entry['takes']})", request_label,
                         f"{agent_cell('score', 1)} / {agent_cell('aligned_score', 1)}",
                         f"{retrieval['score']:.1f} / {retrieval['aligned_score']:.1f}",
                         gap_cell(entry["gaps"]["score"]), gap_cell(entry["gaps"]["aligned_score"]),
                         f"{agent_cell('rough_takes', 0)} / {retrieval['rough_takes']}",
                         f"{agent_cell('worst_style_last_error', 1)} / {retrieval['worst_style_last_error']:.1f}"])
    return rows


def style_rows(results, suffix="_tempo"):
    """Per style: the agents' DTW score (mean over the seeds) and retrieval's, on each set, for one request."""
    entries = [results["sets"][name + suffix] for name in SETS]
    styles = sorted(entries[0]["retrieval"]["by_style"])
    rows = []
    for style in styles:
        cells = []
        for entry in entries:
            agents = np.mean([a["by_style"][style]["aligned_score"] for a in entry["agents"].values()])
            cells += [f"{agents:.1f}", f"{entry['retrieval']['by_style'][style]['aligned_score']:.1f}"]
        rows.append([style, *cells])
    return rows


def ceiling_markdown(results):
    """docs/results/realmocap_ceiling.md from run_ceiling's results."""
    seeds = ", ".join(map(str, results["seeds"]))
    return "\n".join([
        "# Real capture: how near the agent comes to a take it was trained on", "",
        f"The wave agents of the real-capture experiments (preset `{results['preset']}`, {results['epochs']} epochs, "
        f"seeds {seeds}; {results['train_takes']} training takes: 001-008 and 021-036 of the seven styles) asked for "
        "takes they were trained on (007-008) and for the test takes (009-010), each request as the tests make it, "
        "beside nearest-clip retrieval: on the trained takes from the other training takes (never the take asked "
        "for), on the test takes from every training take. RLAnimate's figures are the mean ± sd over the seeds; "
        "the gaps pair the seeds' mean per-take score with retrieval's on the same take (95% interval over the "
        f"takes). Regenerate: `{results['command']}`.", "",
        *markdown_table(["takes", "request", "RLAnimate score / DTW", "retrieval score / DTW", "paired score gap",
                         "paired DTW gap", "takes under 98.5 smoothness: RLAnimate / retrieval",
                         "worst style's last-frame error (deg): RLAnimate / retrieval"], ceiling_rows(results)),
        "", "## DTW score per style, tempo asked", "",
        *markdown_table(["style", "trained takes: RLAnimate", "retrieval (the other takes)", "test takes: RLAnimate",
                         "retrieval"], style_rows(results)),
        "", "## Hand paths, trained takes", "",
        "The right wrist relative to the shoulder in the styles where the first seed's agent trails retrieval most: "
        "the real take (black), the agent trained on it and retrieval from the other takes, both asked its tempo.",
        "", f"![hand paths of trained takes]({results['figure']})", ""])
