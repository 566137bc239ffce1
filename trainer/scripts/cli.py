"""What every trainer script shares: its own arguments under Blender or Python, and clear errors."""
import sys

from rlanimate_addon.core.errors import RLAnimateError


def script_args(argv=None):
    """The script's own arguments: those after `--` under Blender (`blender -b -P script -- ARGS`), else argv[1:]."""
    argv = sys.argv if argv is None else argv
    return argv[argv.index("--") + 1:] if "--" in argv else argv[1:]


def run_main(main, *args):
    """Call main(*args); an RLAnimateError becomes one `error: ...` line on stderr and exit status 2."""
    try:
        return main(*args)
    except RLAnimateError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
