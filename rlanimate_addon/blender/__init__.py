"""The Blender edge: properties, preferences, panel, operators, and the rig and action adapters."""
