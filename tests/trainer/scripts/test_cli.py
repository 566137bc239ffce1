"""What the trainer's scripts share: their own arguments under Blender and Python, errors as exit status 2."""
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
