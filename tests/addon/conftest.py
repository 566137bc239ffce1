"""Fixtures for the extension tests (Blender as the bpy module, background mode)."""
import pytest

pytest.importorskip("bpy")

import addon_helpers  # noqa: E402


@pytest.fixture
def settings():
    """Scene.rlanimate of a factory-fresh, empty scene with the add-on enabled (and disabled after)."""
    yield addon_helpers.enable_addon()
    addon_helpers.disable_addon()


def pytest_sessionfinish(session, exitstatus):
    session.config.rlanimate_exit_status = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    """Blender 4.2 as a Python module segfaults in its own interpreter teardown once the glTF importer or
    Rigify has run (the rig-variant tests use both; 5.0 does not). Every result is reported by now, so
    on 4.x the process leaves with pytest's exit status instead of running that teardown."""
    import os
    import sys

    import bpy
    if bpy.app.version < (5, 0, 0) and hasattr(config, "rlanimate_exit_status"):
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(config.rlanimate_exit_status)


def pytest_collection_modifyitems(config, items):
    """Blender 4.2 as a Python module segfaults in the glTF importer (setting the window's scene) once
    test_rig_variants.py has run in the same process (5.0 does not): there, that file's tests run
    last, after the tests that import real glTF files."""
    import bpy
    if bpy.app.version < (5, 0, 0):
        items.sort(key=lambda item: item.path.name == "test_rig_variants.py")
