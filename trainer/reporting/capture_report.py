"""A capture folder's run: its labels table, and the comparison with retrieval on its held-out takes
(<output>/capture_report.md; trainer/experiments/capture.py)."""
from trainer.motion import capture_folder
from trainer.reporting.behaviour_report import behaviour_words
from trainer.reporting.paired import gap_cell, paired_gap
from trainer.reporting.realmocap_report import PAIRED_MEASURES, take_scores
from trainer.reporting.tables import markdown_table

LABEL_COLUMNS = ("take", "behaviour (kind)", "arm", "label", "tempo", "frames", "split", "notes")
#: How the page names a request (capture.compare_held_out's keys).
REQUESTS = {"paper": "label only (the paper's)", "tempo": "tempo asked"}


def labels_markdown(labels: list) -> list[str]:
    """Lines of the labels table of capture_folder.TakeLabel's."""
    return markdown_table(LABEL_COLUMNS, capture_folder.table_rows(labels))


def _method_cell(result: dict, behaviour: str) -> str:
    entry = result["by_behaviour"][behaviour]
    return f"{result['score']:.1f} / {entry['aligned_score']:.1f} / {result['smoothness']:.2f}"


def _gaps(methods: dict) -> list[str]:
    ours, theirs = take_scores(methods["rlanimate"]), take_scores(methods["nearest_clip"])
    return [gap_cell(paired_gap(ours[key], theirs[key])) for key, _ in PAIRED_MEASURES]


def comparison_rows(results: dict) -> tuple[list[list[str]], list[list[str]]]:
    """(summary rows per behaviour and request, per-take rows) of capture.compare_held_out's results."""
    summary, takes = [], []
    for behaviour, requests in results["behaviours"].items():
        for request, methods in requests.items():
            agent, retrieval = methods["rlanimate"], methods["nearest_clip"]
            words = [behaviour_words(behaviour, result["by_behaviour"][behaviour]) for result in (agent, retrieval)]
            summary.append([behaviour, REQUESTS[request], str(len(agent["clips"])), _method_cell(agent, behaviour),
                            _method_cell(retrieval, behaviour), *_gaps(methods), *words])
            takes += [[ours["name"], behaviour, REQUESTS[request], f"{ours['score']:.1f} / {ours['aligned_score']:.1f}",
                       f"{theirs['score']:.1f} / {theirs['aligned_score']:.1f}"]
                      for ours, theirs in zip(agent["clips"], retrieval["clips"], strict=True)]
    return summary, takes


def fallback_lines(results: dict) -> list[str]:
    """A line per held-out take whose tempo-asked request fell back to its label, and why."""
    return [f"- {take}: asked with its label alone ({why})." for requests in results["behaviours"].values()
            for take, why in requests.get("tempo", {}).get("rlanimate", {}).get("tempo_fallbacks", {}).items()]


def capture_markdown(results: dict) -> str:
    """The capture report page."""
    summary, takes = comparison_rows(results)
    run = results["run"]
    fallbacks = fallback_lines(results)
    lines = ["# Your capture: RLAnimate against retrieval on held-out takes", "",
             f"Takes of `{results['folder']}`, labelled from their names and motion (`trainer/motion/autolabel.py`) "
             f"into `{results['manifest']}`: {results['training_takes']} trained on, {results['held_out_takes']} held "
             f"out by take. Agent: preset `{run['preset']}`, {run['epochs']} epochs, seed {run['seed']}, "
             f"{run['train_cpu_seconds'] / 60:.1f} CPU min of training. Command: `{results['command']}`.", "",
             "Every held-out take's request is answered by the agent (its `agent.npz`, what the add-on plays) and by "
             "nearest-clip retrieval from the training takes, and scored against the take (docs/METRICS.md): score, "
             "DTW score (after time alignment) and smoothness. A wave is asked twice: with its label alone, as the "
             "paper asks, and naming its tempo (the Hz its hand swings at, the panel's Tempo). Gap: the agent's "
             "score minus retrieval's on the same take, mean and 95% interval over the takes.", "",
             *markdown_table(["behaviour", "request", "takes", "RLAnimate score / DTW / smoothness",
                              "retrieval score / DTW / smoothness", "paired score gap (95%)",
                              "paired DTW gap (95%)", "RLAnimate behaviour", "retrieval behaviour"], summary),
             *(["", *fallbacks] if fallbacks else []),
             "", f"Hand paths of held-out takes ({', '.join(results['hand_paths'])}): the take (black), the agent and "
             "retrieval.", "", "![hand paths](capture_hand_paths.png)",
             "", "## Per held-out take (score / DTW score)", "",
             *markdown_table(["take", "behaviour", "request", "RLAnimate", "retrieval"], takes),
             "", "## Labels", "",
             *markdown_table(LABEL_COLUMNS, results["labels"]),
             *(["", *(f"- {note}" for note in results["notes"])] if results["notes"] else []), ""]
    return "\n".join(lines)
