"""Fixtures for the extension tests (Blender as the bpy module, background mode)."""
import pytest

pytest.importorskip("bpy")

import addon_helpers  # noqa: E402


@pytest.fixture
def settings():
    """Scene.rlanimate of a factory-fresh, empty scene with the add-on enabled (and disabled after)."""
    yield addon_helpers.enable_addon()
    addon_helpers.disable_addon()
