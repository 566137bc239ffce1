"""The markdown building blocks of the reports, and Table 4 written with them."""
from trainer.experiments.paper import aggregate
from trainer.reporting.table4 import cell, table4_markdown
from trainer.reporting.tables import markdown_table, page, paragraphs, section, table


def test_markdown_table_has_a_header_a_rule_and_one_line_per_row():
    lines = markdown_table(["clip", "score"], [["a", 1.5], ["b", "-"]], align=["---", "---:"])
    assert lines == ["| clip | score |", "|---|---:|", "| a | 1.5 |", "| b | - |"]


def test_a_page_is_its_blocks_each_ending_in_a_blank_line():
    assert section("Seeds", "First.", "Second.", level=3) == ["### Seeds", "", "First.", "", "Second.", ""]
    assert paragraphs() == [] and table(["a"], [[1]]) == ["| a |", "|---|", "| 1 |", ""]
    text = page(["# Title", ""], section("Part"), table(["a"], [[1]]), paragraphs("End."))
    assert text == "# Title\n\n## Part\n\n| a |\n|---|\n| 1 |\n\nEnd.\n"


def test_markdown_shows_mean_and_sd_only_over_several_seeds():
    assert cell({"mean": 99.123, "sd": 0.05, "n": 3}, 2) == "99.12 ± 0.05"
    assert cell({"mean": 99.123, "sd": 0.0, "n": 1}, 2) == "99.12"
    assert cell({"mean": None, "sd": 0.0, "n": 0}, 2) == "n/a"
    entry = {"requests": 4.0, "score": 99.0, "aligned_score": 99.5, "smoothness": 99.9, "swing_ratio_median": 0.4,
             "frequency_ratio_median": 0.2, "cycles_min": 1.0, "accepted_share": 0.0,
             "elevation_first_error_max": 1.0, "elevation_last_error_max": 2.0}
    agent = aggregate([{"wave": entry}, {"wave": {**entry, "score": 98.0}}])
    baseline = aggregate([{"wave": entry}])
    report = {"settings": "Settings.", "table": {"held-out": {"wave": {"rlanimate": agent, "class_mean": baseline}}},
              "training": {"rlanimate wave seed 0": {"variant": "rlanimate", "column": "wave", "seed": 0, "episodes": 5,
                                                     "train_seconds": 10.0, "train_cpu_seconds": 9.0,
                                                     "held_out_score": 99.0, "seen_score": 99.1}}}
    markdown = table4_markdown(report)
    assert "| RLAnimate | 2 | 98.50 ± 0.71 |" in markdown
    assert "| Class mean | 1 | 99.00 |" in markdown
    assert "wave requests (4)" in markdown


def test_table4_shows_each_pointing_agents_random_target_aim_per_arm_over_seeds():
    per_seed = [{"left": {"median": 1.0, "max": 8.0}, "right": {"median": 2.0, "max": 5.0}},
                {"left": {"median": 3.0, "max": 9.0}, "right": {"median": 2.0, "max": 7.0}}]
    report = {"settings": "Settings.", "table": {}, "training": {}, "random_target_count": 40,
              "random_targets": {"both": {"rlanimate": aggregate(per_seed), "single_state": aggregate(per_seed[:1])}}}
    markdown = table4_markdown(report)
    assert "## Own aim at 40 random unseen targets per arm" in markdown and "the worst of the 40 per arm" in markdown
    assert "| RLAnimate | 2 | 2.0 ± 1.4 | 8.5 ± 0.7 | 2.0 ± 0.0 | 6.0 ± 1.4 |" in markdown
    assert "| single state | 1 | 1.0 | 8.0 | 2.0 | 5.0 |" in markdown
