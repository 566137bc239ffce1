"""The one markdown-table writer of the trainer's reports."""


def markdown_table(header, rows, align=None):
    """Lines of a markdown table: `header` (column titles), `rows` (cells, formatted by str), and `align`
    (one '---' or '---:' per column; default '---')."""
    align = align or ["---"] * len(header)
    return (["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
            + ["| " + " | ".join(str(cell) for cell in row) + " |" for row in rows])
