"""A training run's report.md: every held-out clip scored with the measures named for its behaviour or its kind,
the seen set's share of each behaviour's training clips, and the held-out clips it does not score, with why."""
from trainer.reporting.run_report import report_lines


def _row(name, behaviour, **measures):
    return {"name": name, "behaviour": behaviour, "score": 90.0, "aligned_score": 95.0, "smoothness": 99.0,
            "elevation_first_error": 1.0, "elevation_last_error": 2.0, **measures}


def _summary(rows, **entry):
    return {"requests": len(rows), "score": 90.0, "aligned_score": 95.0, "smoothness": 99.0,
            "elevation_first_error_median": 1.0, "elevation_first_error_max": 1.0,
            "elevation_last_error_median": 2.0, "elevation_last_error_max": 2.0, **entry}


def test_the_report_names_each_clips_measure_by_its_kind_and_says_what_it_does_not_score():
    hello = [_row("hello_left_005", "hello", hand_height_error=0.04, free_arm_rise=0.01)]
    seen = [_row(f"hello_{k}", "hello", hand_height_error=0.02, free_arm_rise=0.0) for k in range(3)]
    kinds = {"hand_height_error_median": 0.04, "hand_height_error_max": 0.04, "free_arm_rise_max": 0.01}
    report = {"variant": "rlanimate", "behaviour": "all", "preset": "debug", "seed": 2, "epochs": 2, "episodes": 4,
              "frames": 400, "train_seconds": 6.0, "train_cpu_seconds": 6.0, "torch_threads": 1,
              "clips": "manifest.json", "skipped_clips": [],
              "held_out": {"clips": hello, "score": 90.0, "smoothness": 99.0, "by_behaviour": {
                  "hello": _summary(hello, **kinds)}},
              "training": {"clips": seen, "score": 90.0, "smoothness": 99.0, "by_behaviour": {
                  "hello": _summary(seen, **kinds)}},
              "training_clips": {"hello": 5},
              "not_scored": [{"name": "wave_left_009", "behaviour": "wave",
                              "why": "the agent was not trained on wave (--behaviour hello)"}]}
    page = "\n".join(report_lines(report))
    assert "| training (seen), hello | 3 of 5 |" in page, "the seen set's share of the behaviour's training clips"
    assert "intensity: hand height error 0.04 arm lengths median (0.04 max), free arm rise 0.01 max" in page
    assert "| hello_left_005 | hello | 90.00 | 95.00 | 99.00 | intensity: hand height error 0.04 arm lengths, " \
           "free arm rise 0.01 |" in page
    assert "Every held-out clip of a trained behaviour is scored (1)" in page
    assert "- wave_left_009: the agent was not trained on wave (--behaviour hello)" in page
    assert "elevation error <=" in page and "elevation error last frame" not in page
