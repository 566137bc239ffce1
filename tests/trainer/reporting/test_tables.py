"""The one markdown-table writer, and Table 4 written with it."""
from trainer.reporting.table4 import table4_markdown
from trainer.reporting.tables import markdown_table


def test_markdown_table_has_a_header_a_rule_and_one_line_per_row():
    lines = markdown_table(["clip", "score"], [["a", 1.5], ["b", "-"]], align=["---", "---:"])
    assert lines == ["| clip | score |", "|---|---:|", "| a | 1.5 |", "| b | - |"]


def test_table4_puts_each_column_in_its_place_and_dashes_missing_runs():
    table = {"rlanimate": {"both": {"score": 91.234, "smoothness": 99.5, "episodes": 200, "train_seconds": 600.4}}}
    seen = {"rlanimate": {"both": {"score": 95.0, "smoothness": 99.6, "cpu_seconds": 580.0}}}
    lines = table4_markdown(table, seen, "Preset `default`.").splitlines()
    assert lines[0] == "# Table 4: final score and smoothness imitating held-out clips" and lines[2] == "Preset `default`."
    assert "| RLAnimate | - | - | - | - | 91.23 | 99.50 |" in lines
    assert "| RLAnimate | both | 200 | 600 | 580 | 95.00 | 99.60 |" in lines
