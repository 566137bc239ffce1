"""The numpy core must import in a Python without Blender: it runs inside the extension and in fast tests.
The trainer's agent/ (torch) and motion/ (numpy) packages must import without Blender too."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _modules(package):
    folder = ROOT / package
    return sorted(".".join(p.relative_to(ROOT).with_suffix("").parts) for p in folder.rglob("*.py"))


#: (package, the top-level modules it must import without): checked in this order in one process, so a
#: module imported by an earlier package was already imported under that package's stricter blocks.
PACKAGES = (("rlanimate_addon/core", ("bpy", "mathutils", "scipy", "torch")),
            ("trainer/motion", ("bpy", "mathutils", "torch")),
            ("trainer/agent", ("bpy", "mathutils")))


def test_packages_import_without_blender():
    stages = [(package, _modules(package), blocked) for package, blocked in PACKAGES]
    assert all(len(modules) > 3 for _, modules, _ in stages), "a package has no modules"
    script = (
        "import sys\n"
        "class Block:\n"
        "    blocked = ()\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in self.blocked:\n"
        "            raise ImportError('blocked ' + name)\n"
        "block = Block()\n"
        "sys.meta_path.insert(0, block)\n"
        f"sys.path.insert(0, {str(ROOT)!r})\n"
        f"for package, modules, blocked in {stages!r}:\n"
        "    block.blocked = blocked\n"
        "    for m in modules:\n"
        "        try:\n"
        "            __import__(m)\n"
        "        except ImportError as error:\n"
        "            sys.exit(f'{package}: {m}: {error}')\n"
        "print('ok')\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
