"""Each trainer script's command line is its settings dataclass (trainer/scripts/cli.py): no arguments give the
dataclass's defaults, every option has help, the options the docs use parse as they did, and bad values are refused.
"""
import ast
import dataclasses
import re
import typing
from pathlib import Path

import pytest
import tyro

from rlanimate_addon.core.errors import RLAnimateError
from trainer.scripts import (
    agent_ablation,
    baselines,
    behaviour,
    cli,
    clip_library,
    contact_sheet,
    experiments,
    realmocap,
    realmocap_ablation,
    realmocap_ceiling,
    realmocap_gestures,
    realmocap_length,
    realmocap_model,
    train,
)

ROOT = Path(__file__).resolve().parents[3]
#: (script, its settings dataclass)
SCRIPTS = ((agent_ablation, agent_ablation.AblationSettings), (baselines, baselines.BaselinesSettings),
           (behaviour, behaviour.BehaviourSettings),
           (clip_library, clip_library.LibrarySettings), (contact_sheet, contact_sheet.SheetSettings),
           (experiments, experiments.PaperSettings), (realmocap, realmocap.RealMocapSettings),
           (realmocap_ablation, realmocap_ablation.AblationSettings),
           (realmocap_ceiling, realmocap_ceiling.CeilingSettings),
           (realmocap_gestures, realmocap_gestures.GestureSettings),
           (realmocap_length, realmocap_length.LengthSettings),
           (realmocap_model, realmocap_model.ModelSettings), (train, train.TrainSettings))


def option_fields(settings_type):
    """The fields of `settings_type` that are options: a nested settings dataclass's own, not those --help hides."""
    for field in dataclasses.fields(settings_type):
        if dataclasses.is_dataclass(field.type):
            yield from option_fields(field.type)
        elif tyro.conf.Suppress not in typing.get_args(field.type)[1:]:
            yield field


def help_entries(settings_type, capsys, monkeypatch):
    """The --help of `settings_type`'s command line, one entry per option: its lines joined, its name and metavar,
    then its help (on its line or the next)."""
    monkeypatch.setenv("COLUMNS", "1000")  # one line per option
    with pytest.raises(SystemExit) as exit_:
        cli.parse_settings(settings_type, ["prog", "--help"], prog="prog", doc="A script.")
    assert exit_.value.code == 0
    entries = []
    for line in capsys.readouterr().out.splitlines():
        text = line.strip("│ ")
        if text.startswith("-"):
            entries.append(text)
        elif entries and text:
            entries[-1] += "  " + text
    return entries


def options_without_help(settings_type, capsys, monkeypatch):
    """The options of `settings_type`'s command line whose --help line says nothing but the default."""
    entries = help_entries(settings_type, capsys, monkeypatch)
    missing = []
    for field in option_fields(settings_type):
        option = "--" + field.name.replace("_", "-")
        entry = next(entry for entry in entries if entry.startswith(option + " "))
        if not re.match(rf"{option}( \S+)*\s\s+\S.*\(default:", entry):  # after the metavar, if any, the help
            missing.append(option)
    return missing


@pytest.mark.parametrize("script, settings_type", SCRIPTS, ids=lambda value: getattr(value, "__name__", ""))
def test_no_arguments_give_the_settings_defaults_and_every_option_has_help(script, settings_type, capsys,
                                                                           monkeypatch):
    assert script.parse_settings(["prog"]) == settings_type()
    assert options_without_help(settings_type, capsys, monkeypatch) == []


def test_an_option_without_a_comment_is_seen(capsys, monkeypatch):
    @dataclasses.dataclass(frozen=True)
    class Settings:
        epochs: int = 3  # iterations of Algorithm 1
        seed: int = 0

    assert options_without_help(Settings, capsys, monkeypatch) == ["--seed"]


def test_the_options_the_docs_use_parse_as_before():
    settings = experiments.parse_settings(["experiments", "--preset", "debug", "--epoch-scale", "0.5", "--seeds", "0",
                                           "1", "--variants", "rlanimate", "supervised", "--columns", "wave",
                                           "--workers", "2", "--skip-training"])
    assert (settings.preset, settings.epoch_scale, settings.seeds, settings.variants, settings.columns,
            settings.workers, settings.skip_training) == ("debug", 0.5, (0, 1), ("rlanimate", "supervised"),
                                                          ("wave",), 2, True)
    assert experiments.parse_settings(["experiments", "--address", "auto"]).address == "auto"
    ablation = agent_ablation.parse_settings(["x", "--only", "point_random_targets", "--targets", "5", "--runs", "r"])
    assert (ablation.only, ablation.targets, ablation.runs) == (("point_random_targets",), 5, "r")
    real = realmocap.parse_settings(["x", "--epochs", "50", "--preset", "end_chunks_wide", "--seeds", "0", "1",
                                     "--point-agent", "a.npz", "--import-workers", "2", "--workers", "3"])
    assert (real.epochs, real.preset, real.seeds, real.point_agent, real.import_workers, real.workers) == (
        50, "end_chunks_wide", (0, 1), "a.npz", 2, 3)
    gestures = realmocap_gestures.parse_settings(["x", "--epochs", "20", "--seeds", "0", "1", "--address", "auto"])
    assert (gestures.epochs, gestures.seeds, gestures.address, gestures.workers) == (20, (0, 1), "auto", 1)
    compared = realmocap_ablation.parse_settings(["x", "--compare-presets", "default", "end_chunks_wide", "default"])
    assert compared.compare_presets == ("default", "end_chunks_wide")
    assert baselines.parse_settings(["x", "--agent", "a.npz", "--clips", "m.json", "--results", "r"]) == \
        baselines.BaselinesSettings(agent="a.npz", clips="m.json", results="r")
    library = clip_library.parse_settings(["x", "--only", "wave_left_006.fbx", "--out", "/tmp/x", "--seed", "7"])
    assert library == clip_library.LibrarySettings(seed=7, out=Path("/tmp/x"), only=("wave_left_006.fbx",))
    measured = behaviour.parse_settings(["x", "--agent", "a.npz", "--targets", "20", "--seeds", "1", "2",
                                         "--target-seed", "7"])
    assert measured == behaviour.BehaviourSettings(agent="a.npz", targets=20, seeds=(1, 2), target_seed=7)
    sheet = contact_sheet.parse_settings(["x", "--generated", "--further", "--agent", "runs/four/agent.npz",
                                          "--out", "x.png"])
    assert sheet == contact_sheet.SheetSettings(out=Path("x.png"), generated=True, further=True,
                                                agent=Path("runs/four/agent.npz"))


def test_blenders_own_arguments_before_the_double_dash_are_not_the_scripts():
    settings = experiments.parse_settings(["blender", "-b", "-P", "x.py", "--", "--seeds", "4"])
    assert settings.seeds == (4,)


def test_bad_values_are_refused_with_a_message(capsys):
    for argv in (["x", "--variants", "rlanimat"], ["x", "--epoch-scale", "half"], ["x", "--seed", "1"]):
        with pytest.raises(SystemExit) as exit_:
            experiments.parse_settings(argv)
        assert exit_.value.code == 2
        assert argv[1] in capsys.readouterr().err
    with pytest.raises(SystemExit):
        agent_ablation.parse_settings(["x", "--only", "wave"])
    with pytest.raises(RLAnimateError, match="--seeds given no value: give one or more, such as 0 1 2"):
        realmocap.parse_settings(["x", "--seeds"])
    with pytest.raises(RLAnimateError, match="--variants given no value"):
        experiments.parse_settings(["x", "--variants"])
    with pytest.raises(RLAnimateError, match="--seeds needs at least two different seeds, none of them 0"):
        behaviour.parse_settings(["x", "--seeds", "0", "1"])


def test_the_extension_never_imports_the_trainers_command_line_library():
    importers = []
    for path in (ROOT / "rlanimate_addon").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = ([alias.name for alias in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(name.split(".")[0] == "tyro" for name in names):
                importers.append(str(path.relative_to(ROOT)))
    assert importers == []


def test_a_nested_settings_dataclass_gives_its_options_without_a_prefix():
    @dataclasses.dataclass(frozen=True)
    class Run:
        epochs: int = 50  # iterations of Algorithm 1

    @dataclasses.dataclass(frozen=True)
    class Command:
        run: Run = Run()
        install: bool = False  # install the agent

    assert cli.parse_settings(Command, ["x", "--epochs", "3", "--install"], prog="x", doc=None) == \
        Command(Run(epochs=3), install=True)
