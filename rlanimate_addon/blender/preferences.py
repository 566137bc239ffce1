"""Add-on preferences (which agent file to use) and loading of the selected agent.

The preferences are looked up under the add-on's own module name, derived from `__package__`, so
they are found both as a legacy add-on (`rlanimate_addon`) and as an extension
(`bl_ext.<repository>.rlanimate`).
"""
from pathlib import Path

import bpy

from ..core import behaviours
from ..core.errors import RLAnimateError
from . import file_versions

_PARTS = __package__.split(".")
#: The add-on's module name: the package above rlanimate_addon (the extension), else rlanimate_addon.
ADDON_PACKAGE = ".".join(_PARTS[:_PARTS.index("rlanimate_addon")]) or "rlanimate_addon"
BUNDLED_AGENT = Path(__file__).resolve().parents[1] / "agents" / "default.npz"

#: The agent read, or why it could not be, for the latest file version asked for.
_agents = file_versions.PerVersion(kept=1)


class RLANIMATE_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_PACKAGE

    agent_path: bpy.props.StringProperty(
        name="Agent File", subtype="FILE_PATH",
        description="An agent exported by the RLAnimate trainer (.npz); leave empty for the bundled agent")

    def draw(self, context):
        self.layout.prop(self, "agent_path")
        self.layout.label(text="Empty: the bundled default agent.", icon="INFO")
        try:
            performs = ", ".join(behaviours.title(b) for b in selected_agent(context).behaviours)
        except RLAnimateError as error:
            self.layout.label(text=str(error), icon="ERROR")
        else:
            self.layout.label(text=f"Behaviours: {performs}", icon="ARMATURE_DATA")


def selected_agent_path(context):
    """Path of the agent chosen in the preferences, or the bundled default."""
    addon = context.preferences.addons.get(ADDON_PACKAGE)
    chosen = addon.preferences.agent_path if addon is not None and addon.preferences else ""
    return Path(bpy.path.abspath(chosen)) if chosen else BUNDLED_AGENT


def load_agent(path):
    """The agent at `path`, loaded once per file version; RLAnimateError when missing or damaged.

    A failure is cached like a success, per path, modification time and size: the panel asks on every
    redraw, and a bad file is read once, not on each of them.
    """
    from ..core import runtime

    path = Path(path)
    if file_versions.version(path) is None:
        raise RLAnimateError(f"Agent file {path} does not exist: choose another in Preferences > Add-ons > "
                             "RLAnimate, or clear it to use the bundled agent.")
    return _agents.read(path, runtime.load_agent)


def selected_agent(context):
    """The agent chosen in the preferences (or the bundled one), loaded."""
    return load_agent(selected_agent_path(context))
