"""The numpy core must import in a Python without Blender: it runs inside the extension and in fast tests.
The trainer's agent/ (torch) and motion/ (numpy) packages must import without Blender too."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _modules(package):
    folder = ROOT / package
    return sorted(".".join(p.relative_to(ROOT).with_suffix("").parts) for p in folder.rglob("*.py"))


def _import_blocking(modules, blocked):
    script = (
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        f"        if name.split('.')[0] in {tuple(blocked)!r}:\n"
        "            raise ImportError('blocked ' + name)\n"
        "sys.meta_path.insert(0, Block())\n"
        f"sys.path.insert(0, {str(ROOT)!r})\n"
        f"for m in {modules!r}:\n"
        "    __import__(m)\n"
        "print('ok')\n"
    )
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)


@pytest.mark.parametrize("package, blocked", [
    ("rlanimate_addon/core", ("bpy", "mathutils", "scipy", "torch")),
    ("trainer/agent", ("bpy", "mathutils")),
    ("trainer/motion", ("bpy", "mathutils", "torch")),
])
def test_package_imports_without_blender(package, blocked):
    modules = _modules(package)
    assert len(modules) > 3, f"no modules found in {package}"
    result = _import_blocking(modules, blocked)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
