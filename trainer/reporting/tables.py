"""The markdown building blocks of the trainer's reports: tables, headed sections and paragraphs, each block's
lines ending in a blank line, so that a page is its blocks' lines joined by newlines."""
from collections.abc import Sequence


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[object]], align: Sequence[str] | None = None
                   ) -> list[str]:
    """Lines of a markdown table: `header` (column titles), `rows` (cells, formatted by str), and `align`
    (one '---' or '---:' per column; default '---')."""
    align = align or ["---"] * len(header)
    return (["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
            + ["| " + " | ".join(str(cell) for cell in row) + " |" for row in rows])


def table(header: Sequence[str], rows: Sequence[Sequence[object]], align: Sequence[str] | None = None) -> list[str]:
    """A markdown table's lines (markdown_table) and the blank line after them."""
    return [*markdown_table(header, rows, align), ""]


def paragraphs(*texts: str) -> list[str]:
    """Lines of paragraphs (or list items, images), each followed by a blank line."""
    return [line for text in texts for line in (text, "")]


def section(title: str, *texts: str, level: int = 2) -> list[str]:
    """Lines of a heading of `level` and the paragraphs under it (paragraphs)."""
    return [f"{'#' * level} {title}", "", *paragraphs(*texts)]


def page(*blocks: Sequence[str]) -> str:
    """The page of blocks of lines (each ending in a blank line, so the page ends in a newline)."""
    return "\n".join(line for block in blocks for line in block)
