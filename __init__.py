"""Blender extension entry point: the repository root is the extension's source directory.

Everything is registered by the rlanimate_addon package; this file only delegates to it.
"""
from .rlanimate_addon import glTF2ImportUserExtension, register, unregister

__all__ = ("glTF2ImportUserExtension", "register", "unregister")
