"""The numpy core must import in a Python without Blender: it runs inside the extension and in fast tests."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CORE = ROOT / "rlanimate_addon" / "core"


def test_core_modules_import_without_bpy_mathutils_or_scipy():
    modules = sorted(p.stem for p in CORE.glob("*.py") if p.stem != "__init__")
    assert modules, "no core modules found"
    script = (
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in ('bpy', 'mathutils', 'scipy', 'torch'):\n"
        "            raise ImportError('blocked ' + name)\n"
        "sys.meta_path.insert(0, Block())\n"
        f"sys.path.insert(0, {str(ROOT)!r})\n"
        f"for m in {modules!r}:\n"
        "    __import__('rlanimate_addon.core.' + m)\n"
        "print('ok')\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
