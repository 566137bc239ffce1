"""The one domain error type: raised by bpy-free code, turned into user messages at the edges."""


class RLAnimateError(Exception):
    """A problem the user can fix: the message names the problem and the fix."""
