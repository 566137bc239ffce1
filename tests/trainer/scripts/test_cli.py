"""What the trainer's scripts share: their own arguments under Blender and Python, errors as exit status 2, results
written as JSON and a page."""
import json

from rlanimate_addon.core.errors import RLAnimateError
from trainer.scripts import cli


def test_script_args_under_blender_and_python():
    assert cli.script_args(["blender", "-b", "-P", "x.py", "--", "--epochs", "3"]) == ["--epochs", "3"]
    assert cli.script_args(["x.py", "--epochs", "3"]) == ["--epochs", "3"]


def test_an_rlanimate_error_is_one_line_on_stderr_and_status_2(capsys):
    def failing():
        raise RLAnimateError("No clips: add some.")

    assert cli.run_main(failing) == 2
    assert capsys.readouterr().err == "error: No clips: add some.\n"
    assert cli.run_main(lambda value: value, 0) == 0


def test_write_results_writes_the_json_and_the_page_and_prints_the_page(tmp_path, capsys):
    folder = tmp_path / "results" / "new"
    cli.write_results(folder, "experiment", {"score": [1.5, None]}, "# Experiment\n")
    assert json.loads((folder / "experiment.json").read_text()) == {"score": [1.5, None]}
    assert (folder / "experiment.md").read_text() == "# Experiment\n"
    assert capsys.readouterr().out == "# Experiment\n\n"
