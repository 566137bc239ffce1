"""What every trainer script shares: its own arguments under Blender or Python, clear errors, and its results
written as JSON beside a Markdown page."""
import json
import sys
from pathlib import Path

from rlanimate_addon.core.errors import RLAnimateError


def script_args(argv=None):
    """The script's own arguments: those after `--` under Blender (`blender -b -P script -- ARGS`), else argv[1:]."""
    argv = sys.argv if argv is None else argv
    return argv[argv.index("--") + 1:] if "--" in argv else argv[1:]


#: What an experiment that trains its runs as Ray tasks says when it is interrupted.
RUNS_INTERRUPTED = ("interrupted: the finished runs are kept, and the others continue from their checkpoints when "
                    "the command runs again")


def run_main(main, *args, interrupted="interrupted"):
    """Call main(*args); an RLAnimateError becomes one `error: ...` line on stderr and exit status 2, a
    Ctrl-C (KeyboardInterrupt) the line `interrupted` and exit status 130."""
    try:
        return main(*args)
    except RLAnimateError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(interrupted, file=sys.stderr)
        return 130


def add_real_capture_arguments(parser, defaults):
    """--realmocap, --runs, --results and --workers, each defaulting to the field of that name of `defaults` (a
    real-capture script's settings)."""
    parser.add_argument("--realmocap", default=defaults.realmocap)
    parser.add_argument("--runs", default=defaults.runs)
    parser.add_argument("--results", default=defaults.results)
    parser.add_argument("--workers", type=int, default=defaults.workers,
                        help="training runs at a time on a local Ray (default: one per CPU)")


def write_results(folder, name, results, page):
    """Write `results` to <folder>/<name>.json and the `page` to <folder>/<name>.md, and print the page."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.json").write_text(json.dumps(results, indent=2) + "\n")
    (folder / f"{name}.md").write_text(page)
    print(page)
