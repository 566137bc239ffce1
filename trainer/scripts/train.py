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
import argparse
from pathlib import Path

from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent.models import VARIANTS
from trainer.blender_io.clip_session import LibrarySession
from trainer.blender_io.import_worker import ImportLimits
from trainer.experiments import capture
from trainer.experiments.run import NEW_RUN_DEFAULTS, RunSettings, check_settings, resolve, train
from trainer.files import atomic_copy
from trainer.paths import DEFAULT_OUTPUT, INSTALLED_AGENT, RESULTS_DIR, shown
from trainer.scripts.cli import run_main, script_args

#: What an interrupted run says: every epoch it finished is in its checkpoint.
INTERRUPTED = "interrupted: the run's checkpoint holds every epoch it finished; continue it with --resume"


def build_parser():
    """The command line. Run settings default to None ("not given"): a new run takes NEW_RUN_DEFAULTS, a
    resumed run its checkpoint's values."""
    defaults = NEW_RUN_DEFAULTS
    parser = argparse.ArgumentParser(prog="trainer/train.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--behaviour", help="the behaviours to learn: all (every behaviour of the clip library), "
                                             "both (point and wave), one behaviour (point), or several joined by "
                                             f"commas (point,beckon); default {defaults['behaviour']}")
    parser.add_argument("--clips", help="clip library: a manifest.json or the folder that holds one (default "
                                        "sample_rigs/clips); or a folder of .bvh/.fbx takes without one, which is "
                                        "labelled from the takes' names and motion into <output>/manifest.json")
    parser.add_argument("--hold-out", type=float, default=capture.capture_folder.HOLD_OUT_SHARE,
                        help="with a folder of takes: the share of each behaviour and arm's takes held out for "
                             "the comparison with retrieval (default %(default)s)")
    parser.add_argument("--epochs", type=int,
                        help="iterations of Algorithm 1 (default: the preset's, the paper's 50 for one behaviour "
                             "and 100 for both; on --resume, the run's own)")
    parser.add_argument("--seed", type=int, help=f"default {defaults['seed']}")
    parser.add_argument("--output", default=str(DEFAULT_OUTPUT))
    parser.add_argument("--preset", help="config preset: debug, default or paper (default default)")
    parser.add_argument("--variant", choices=VARIANTS, help="ablation variant (Table 4; default rlanimate)")
    parser.add_argument("--resume", action="store_true",
                        help="continue the run in --output from its checkpoint, with the run's own settings")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace the run in --output (without it, a new run into a run's folder is refused)")
    parser.add_argument("--allow-new-behaviour", action="store_true",
                        help="with --behaviour all, also learn a behaviour other than point and wave that fewer "
                             "than 3 clips name (without it, such a behaviour is refused as a likely typo)")
    parser.add_argument("--install", action="store_true",
                        help="install the agent as the add-on's default and its report into docs/results/")
    parser.add_argument("--eval-every", type=int,
                        help=f"evaluate on seen and unseen clips every N epochs (0: only at the end; default "
                             f"{defaults['eval_every']})")
    parser.add_argument("--checkpoint-every", type=int, default=1)
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--verbose", action="store_true", help="show what Blender prints while loading the clips")
    parser.add_argument("--import-workers", type=int, default=1,
                        help="import the clips the cache lacks with N Blenders at once (worker processes; default 1)")
    parser.add_argument("--import-memory-limit", type=float, default=ImportLimits.memory_gb, metavar="GB",
                        help="the memory one clip's import may take; a clip that needs more is skipped with a note "
                             f"(default {ImportLimits.memory_gb:g})")
    parser.add_argument("--import-time-limit", type=float, default=ImportLimits.seconds, metavar="SECONDS",
                        help="the time one clip's import may take; a clip that takes longer is skipped with a note "
                             f"(default {ImportLimits.seconds:g})")
    return parser


def import_limits(args: argparse.Namespace) -> ImportLimits:
    """The ImportLimits of the arguments; RLAnimateError naming each that is not a positive number."""
    problems = [f"{option} {value:g}: give a number above 0{example}" for option, value, example in (
        ("--import-workers", args.import_workers, ", such as 2"),
        ("--import-memory-limit", args.import_memory_limit, " (GB), such as 2"),
        ("--import-time-limit", args.import_time_limit, " (seconds), such as 60")) if not value > 0]
    if problems:
        raise RLAnimateError("; ".join(problems) + ". Nothing was trained.")
    return ImportLimits(memory_gb=args.import_memory_limit, seconds=args.import_time_limit)


def run_settings(args):
    """RunSettings from parsed arguments."""
    return RunSettings(output=args.output, behaviour=args.behaviour, clips=args.clips, epochs=args.epochs,
                       seed=args.seed, preset=args.preset, variant=args.variant, eval_every=args.eval_every,
                       resume=args.resume, overwrite=args.overwrite, allow_new_behaviour=args.allow_new_behaviour,
                       checkpoint_every=args.checkpoint_every, progress=not args.quiet)


def install(output):
    """Copy a run's agent into the add-on (atomically) and its report and curves into docs/results/."""
    atomic_copy(output / "agent.npz", INSTALLED_AGENT)
    for source, target in (("report.json", "default_agent.json"), ("report.md", "default_agent.md"),
                           ("training_curves.png", "default_agent_curves.png")):
        atomic_copy(output / source, RESULTS_DIR / target)


def main(argv=None):
    args = build_parser().parse_args(script_args(argv))
    settings = run_settings(args)
    labelled = None
    if not args.resume and capture.is_capture_folder(args.clips):  # a studio's folder of takes, no manifest
        check_settings(settings)
        labelled = capture.label_folder(args.clips, args.output, args.hold_out, args.verbose)
        settings = capture.capture_settings(settings, labelled)
    settings = resolve(settings)
    limits = import_limits(args)
    session = LibrarySession(settings.clips, verbose=args.verbose, import_workers=args.import_workers,
                             import_limits=limits)
    report, _ = train(settings, session)
    scored, split = ((report["held_out"], "held-out") if report["held_out"] is not None
                     else (report["training"], "no held-out clips; training-clip"))
    print(f"trained: {report['epochs']} epochs, {report['episodes']} episodes, {report['train_seconds'] / 60:.1f} min; "
          f"{split} score {scored['score']:.2f}, smoothness {scored['smoothness']:.2f}; outputs in {args.output}")
    if labelled is not None:
        page = capture.write_report(labelled, report, session, args.output, " ".join(["trainer/train.py",
                                                                                      *script_args(argv)]))
        print(f"compared with retrieval on the held-out takes: {page}")
    if args.install:
        install(Path(settings.output))
        print(f"installed: {shown(INSTALLED_AGENT)}, and the report in {shown(RESULTS_DIR)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_main(main, interrupted=INTERRUPTED))
