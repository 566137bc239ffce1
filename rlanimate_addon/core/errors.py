"""The one domain error type: raised by bpy-free code, turned into user messages at the edges."""
import re


class RLAnimateError(Exception):
    """A problem the user can fix: the message names the problem and the fix."""


_NAMED_ERROR = re.compile(r"[A-Za-z_.]*(Error|Exception): ")


def operator_error_reason(error: BaseException) -> str:
    """The one-line reason in the RuntimeError a failing `bpy.ops` call raises: the last line that names
    a Python error ("IndexError: list index out of range"), not the traceback or "Location: .../ops.py"."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    named = [line for line in lines if _NAMED_ERROR.match(line)]
    if named:
        return named[-1]
    others = [line for line in lines if not line.startswith("Location:")]
    return others[-1] if others else type(error).__name__
