"""Train an RLAnimate agent (Algorithm 1) and write the agent, its report and plots.

    python -m trainer.scripts.train [ARGS]        (or python trainer/train.py [ARGS])
    blender -b -P trainer/train.py -- [ARGS]      (Blender's Python finds torch through a venv of
                                                   the same minor version on PYTHONPATH; see README)

With no arguments it trains the RLAnimate agent of every behaviour of the sample clip library into
runs/default/. `--clips FOLDER` on a folder of .bvh/.fbx takes without a manifest labels the takes from their
names and motion (shown as a table and written to <output>/manifest.json), holds out a share of them, trains,
and compares the agent with retrieval on the held-out takes in <output>/capture_report.md
(trainer/experiments/capture.py). `--install` also copies the agent to rlanimate_addon/agents/default.npz and its
report to docs/results/. Outputs: see trainer/experiments/run.py. `--resume` continues the run in --output
from its checkpoint with the run's own settings; the continuation equals the uninterrupted run. A new run
into the folder of another is refused unless `--overwrite`.
"""
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated

import tyro

from rlanimate_addon.core.errors import RLAnimateError
from trainer.blender_io.clip_session import LibrarySession
from trainer.blender_io.import_worker import ImportLimits
from trainer.experiments import capture
from trainer.experiments.run import RunSettings, check_settings, resolve, train
from trainer.files import atomic_copy
from trainer.paths import DEFAULT_OUTPUT, INSTALLED_AGENT, RESULTS_DIR, shown
from trainer.scripts import cli
from trainer.scripts.cli import run_main, script_args

#: What an interrupted run says: every epoch it finished is in its checkpoint.
INTERRUPTED = "interrupted: the run's checkpoint holds every epoch it finished; continue it with --resume"


@dataclass(frozen=True)
class TrainSettings:
    """The train command: a run (its options unprefixed: --epochs, --output), and what to do around it."""
    run: RunSettings = RunSettings(output=str(DEFAULT_OUTPUT))
    # with a folder of takes: the share of each behaviour and arm's takes held out for the comparison with retrieval
    hold_out: float = capture.capture_folder.HOLD_OUT_SHARE
    install: bool = False  # install the agent as the add-on's default and its report into docs/results/
    quiet: bool = False  # no progress bar
    verbose: bool = False  # show what Blender prints while loading the clips
    import_workers: int = 1  # import the clips the cache lacks with N Blenders at once (worker processes)
    # the memory one clip's import may take; a clip that needs more is skipped with a note
    import_memory_limit: Annotated[float, tyro.conf.arg(metavar="GB")] = ImportLimits.memory_gb
    # the time one clip's import may take; a clip that takes longer is skipped with a note
    import_time_limit: Annotated[float, tyro.conf.arg(metavar="SECONDS")] = ImportLimits.seconds


def parse_settings(argv: Sequence[str] | None = None) -> TrainSettings:
    """TrainSettings from the command line."""
    return cli.parse_settings(TrainSettings, argv, prog="trainer/train.py", doc=__doc__)


def import_limits(settings: TrainSettings) -> ImportLimits:
    """The ImportLimits of the settings; RLAnimateError naming each that is not a positive number."""
    problems = [f"{option} {value:g}: give a number above 0{example}" for option, value, example in (
        ("--import-workers", settings.import_workers, ", such as 2"),
        ("--import-memory-limit", settings.import_memory_limit, " (GB), such as 2"),
        ("--import-time-limit", settings.import_time_limit, " (seconds), such as 60")) if not value > 0]
    if problems:
        raise RLAnimateError("; ".join(problems) + ". Nothing was trained.")
    return ImportLimits(memory_gb=settings.import_memory_limit, seconds=settings.import_time_limit)


def install(output: Path) -> None:
    """Copy a run's agent into the add-on (atomically) and its report and curves into docs/results/."""
    atomic_copy(output / "agent.npz", INSTALLED_AGENT)
    for source, target in (("report.json", "default_agent.json"), ("report.md", "default_agent.md"),
                           ("training_curves.png", "default_agent_curves.png")):
        atomic_copy(output / source, RESULTS_DIR / target)


def main(argv: Sequence[str] | None = None) -> int:
    command = parse_settings(argv)
    settings = replace(command.run, progress=not command.quiet)
    output = settings.output
    limits = import_limits(command)  # before a capture folder's takes are imported and labelled
    labelled = None
    if not settings.resume and capture.is_capture_folder(settings.clips):  # a studio's folder of takes, no manifest
        check_settings(settings)
        labelled = capture.label_folder(settings.clips, output, command.hold_out, command.verbose)
        settings = capture.capture_settings(settings, labelled)
    settings = resolve(settings)
    session = LibrarySession(settings.clips, verbose=command.verbose, import_workers=command.import_workers,
                             import_limits=limits)
    report, _ = train(settings, session)
    scored, split = ((report["held_out"], "held-out") if report["held_out"] is not None
                     else (report["training"], "no held-out clips; training-clip"))
    print(f"trained: {report['epochs']} epochs, {report['episodes']} episodes, {report['train_seconds'] / 60:.1f} min; "
          f"{split} score {scored['score']:.2f}, smoothness {scored['smoothness']:.2f}; outputs in {output}")
    if labelled is not None:
        page = capture.write_report(labelled, report, session, output, " ".join(["trainer/train.py",
                                                                                 *script_args(argv)]))
        print(f"compared with retrieval on the held-out takes: {page}")
    if command.install:
        install(Path(settings.output))
        print(f"installed: {shown(INSTALLED_AGENT)}, and the report in {shown(RESULTS_DIR)}")
    return 0

if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=INTERRUPTED))
