"""The training-length search on validation takes as a page (docs/results/realmocap_length.md)."""
from trainer.reporting.realmocap_report import SEED_METRICS, metric_cells
from trainer.reporting.tables import markdown_table

_REQUESTS = {"paper": "the paper's", "_tempo": "with the tempo"}


def length_rows(results):
    """Per validation set, request and length: RLAnimate's measures (realmocap_report.SEED_METRICS) and its
    training CPU time; retrieval last."""
    rows = []
    for entry in results["experiments"].values():
        label = f"{entry['validates']} ({entry['validation_clips']})"
        for request, request_label in _REQUESTS.items():
            for length, scored in entry["by_length"].items():
                *cells, accepted = metric_cells(scored[request], SEED_METRICS)
                rows.append([label, request_label, f"RLAnimate, {length} epochs", *cells,
                             f"{accepted}/{entry['validation_clips']}", f"{scored['train_cpu_seconds']:.0f}"])
            *cells, accepted = metric_cells(entry["retrieval"][request], SEED_METRICS)
            rows.append([label, request_label, "Nearest clip", *cells, f"{accepted}/{entry['validation_clips']}", ""])
    return rows


def rhythm_rule_rows(results):
    """Per validation set and rhythm rule: the chosen length's agent's measures for the paper's request, and the
    rule on the training waves alone (rate within 0.8-1.25x, median |log rate ratio|)."""
    rows = []
    for name, entry in results["experiments"].items():
        label = f"{entry['validates']} ({entry['validation_clips']})"
        for rule, played in results["rhythm_rules"].items():
            *cells, accepted = metric_cells(played["sets"][name]["paper"], SEED_METRICS)
            check = played["sets"][name]["leave_one_out"]
            rows.append([label, rule, *cells, f"{accepted}/{entry['validation_clips']}",
                         f"{check['rate_within']:.0%}", f"{check['median_log_rate_error']:.3f}"])
    return rows


def length_markdown(results):
    """docs/results/realmocap_length.md from run_lengths's results."""
    sets = "; ".join(f"*{entry['validates']}*: {entry['train_clips']} training clips, {entry['validation_clips']} "
                     f"validation clips" for entry in results["experiments"].values())
    lines = ["# How long to train on real capture, chosen on validation takes", "",
             "Before the tests, from their training takes only (trainer/experiments/realmocap_length.py): agents "
             "trained as the wave agent is but for takes 007-008 of its 5 styles that are not the unseen styles are "
             "scored on those (as the wave agent is on takes 009-010), and agents trained on 4 styles on the "
             f"fifth, normal (as the hold-out agent is on its 2 unseen styles). {sets}. Training seed "
             f"{results['seed']}, preset `{results['preset']}`, each length trained from the start. Regenerate: "
             f"`{results['command']}`.", "",
             f"**Chosen: {results['chosen']} epochs**, the best mean of score and DTW score over both validation "
             "sets with the paper's request (the shorter on a tie).", "",
             *markdown_table(["validation set", "request", "method", "score", "DTW score", "swing ratio",
                              "frequency ratio", "last-frame elevation error (deg)", "accepted",
                              "training CPU s"], length_rows(results)), "",
             "## The rhythm at play time", "",
             f"The {results['chosen']}-epoch agents played with each rhythm rule, nothing retrained, on the paper's "
             "requests (core/rhythm.py): the exaggeration kernel's sd and the tempo kernel's sd in log Hz (the "
             "training waves near the request's exaggeration and tempo weigh in its rhythm by Gaussians of these), "
             "and whether a request weighs the training waves of its own arm or of both; and each rule judged on "
             "the agents' training waves alone, each left out in turn and its rate predicted from the rest "
             "(trainer/evaluation/rhythm_leave_one_out.py). "
             f"**Chosen: {results['chosen_rhythm_rule']}**, the best mean of score and DTW score over both "
             "validation sets (the first listed on a tie).", "",
             *markdown_table(["validation set", "rhythm rule", "score", "DTW score", "swing ratio",
                              "frequency ratio", "last-frame elevation error (deg)", "accepted",
                              "training waves: rate within 0.8-1.25x", "median abs log rate ratio"],
                             rhythm_rule_rows(results)), ""]
    return "\n".join(lines)
