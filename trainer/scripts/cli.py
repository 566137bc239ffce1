"""What every trainer script shares: its command line made from its settings dataclass, its own arguments under
Blender or Python, clear errors, and its results written as JSON beside a Markdown page."""
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TypeVar

import tyro

from rlanimate_addon.core.errors import RLAnimateError

Settings = TypeVar("Settings")


def script_args(argv: Sequence[str] | None = None) -> list[str]:
    """The script's own arguments: those after `--` under Blender (`blender -b -P script -- ARGS`), else argv[1:]."""
    argv = list(sys.argv if argv is None else argv)
    return argv[argv.index("--") + 1:] if "--" in argv else argv[1:]


def parse_settings(settings_type: type[Settings], argv: Sequence[str] | None = None, *, prog: str,
                   doc: str | None) -> Settings:
    """A `settings_type` (a frozen settings dataclass) from the command line `argv` (sys.argv when None; see
    script_args): each field is an option named as it is with hyphens (`epoch_scale`: `--epoch-scale`), its
    comment the help, its default the dataclass's; a tuple takes several values (`--seeds 0 1`), a bool is a flag
    (`--skip-training`). --help shows them with `prog` and the first paragraph of the script's `doc`; a bad value
    exits with status 2 and a message, as argparse does. The dataclass checks the values it is given
    (__post_init__ raising RLAnimateError). A field that is itself a settings dataclass gives its fields' options
    without a prefix (`--epochs`, not `--run.epochs`)."""
    return tyro.cli(settings_type, args=script_args(argv), prog=prog, description=(doc or "").split("\n\n")[0],
                    config=(tyro.conf.FlagCreatePairsOff, tyro.conf.OmitArgPrefixes))


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


def write_results(folder, name, results, page):
    """Write `results` to <folder>/<name>.json and the `page` to <folder>/<name>.md, and print the page."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.json").write_text(json.dumps(results, indent=2) + "\n")
    (folder / f"{name}.md").write_text(page)
    print(page)
