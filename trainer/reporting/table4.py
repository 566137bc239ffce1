"""Table 4 as markdown: final held-out score and smoothness per variant and column, and each run's details."""
from trainer.reporting.plots import COLUMN_LABELS, VARIANT_LABELS
from trainer.reporting.tables import markdown_table


def table4_markdown(table, seen, settings):
    """table: {variant: {column: {score, smoothness, episodes, train_seconds}}}; seen: {variant: {column:
    {score, smoothness, cpu_seconds}}} on training clips; settings: the line that says how the runs were made."""
    rows = []
    for variant, columns in table.items():
        cells = []
        for column in COLUMN_LABELS:
            entry = columns.get(column)
            cells += [f"{entry['score']:.2f}", f"{entry['smoothness']:.2f}"] if entry else ["-", "-"]
        rows.append([VARIANT_LABELS[variant]] + cells)
    details = [[VARIANT_LABELS[variant], column, entry["episodes"], f"{entry['train_seconds']:.0f}",
                f"{seen[variant][column]['cpu_seconds']:.0f}", f"{seen[variant][column]['score']:.2f}",
                f"{seen[variant][column]['smoothness']:.2f}"]
               for variant, columns in table.items() for column, entry in columns.items()]
    lines = ["# Table 4: final score and smoothness imitating held-out clips", "", settings, "",
             *markdown_table(["variant", "wave score", "wave smooth.", "point score", "point smooth.", "both score",
                              "both smooth."], rows),
             "", "Sample episodes, training time (wall clock and CPU seconds, on a machine shared with other "
             "jobs) and score on 10 training (seen) clips per run:", "",
             *markdown_table(["variant", "column", "episodes", "wall s", "CPU s", "seen score", "seen smooth."],
                             details)]
    return "\n".join(lines) + "\n"
