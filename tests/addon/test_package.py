"""The repository is a valid extension: Blender's validator passes, and the built zip installs and enables."""
import json
import os
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[2]
#: Blender's extension tool, shipped with the bpy module.
BLENDER_EXT = Path(bpy.utils.system_resource("SCRIPTS")) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"


def _blender_ext(*args, cwd=ROOT):
    result = subprocess.run([sys.executable, str(BLENDER_EXT), *args], cwd=cwd, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def test_manifest_validates():
    assert "Success" in _blender_ext("validate", str(ROOT))


def _build(out_dir):
    out_dir.mkdir(parents=True, exist_ok=True)
    _blender_ext("build", "--source-dir", str(ROOT), "--output-dir", str(out_dir))
    (package,) = out_dir.glob("rlanimate-*.zip")
    return package


def test_built_zip_holds_only_the_add_on(tmp_path):
    with zipfile.ZipFile(_build(tmp_path)) as package:
        names = package.namelist()
    assert {"blender_manifest.toml", "__init__.py", "rlanimate_addon/__init__.py",
            "rlanimate_addon/blender/registration.py", "rlanimate_addon/core/gesture.py",
            "wheels/threadpoolctl-3.8.0-py3-none-any.whl"} <= set(names)
    for excluded in ("trainer/", "tests/", "docs/", "benchmarks/", "sample_rigs/", ".ci/", "scripts/"):
        assert not any(n.startswith(excluded) for n in names), excluded
    assert not any("__pycache__" in n or n.endswith(".pyc") for n in names)


CHECK = textwrap.dedent("""
    import json, sys
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.extensions.package_install_files(filepath=sys.argv[-1], repo="user_default",
                                                      enable_on_install=True)
    name = "bl_ext.user_default.rlanimate"
    addon = bpy.context.preferences.addons.get(name)
    module = sys.modules.get(name + ".rlanimate_addon.blender.preferences")
    print(json.dumps({
        "result": sorted(result),
        "enabled": addon is not None,
        "preferences": addon is not None and addon.preferences is not None
                       and addon.preferences.bl_rna.identifier == "RLANIMATE_AP_preferences",
        "scene_settings": hasattr(bpy.types.Scene, "rlanimate"),
        "operators": sorted(op for op in dir(bpy.ops.rlanimate) if not op.startswith("_")),
        "module_file": getattr(module, "__file__", ""),
    }))
""")


def test_built_zip_installs_and_enables_in_a_fresh_session(tmp_path):
    package = _build(tmp_path / "build")
    user = tmp_path / "user"
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    env.update({"BLENDER_USER_RESOURCES": str(user), "BLENDER_USER_CONFIG": str(user / "config"),
                "BLENDER_USER_SCRIPTS": str(user / "scripts"), "BLENDER_USER_EXTENSIONS": str(user / "extensions"),
                "BLENDER_USER_DATAFILES": str(user / "datafiles")})
    result = subprocess.run([sys.executable, "-c", CHECK, str(package)], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-3000:]
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert report["result"] == ["FINISHED"]
    assert report["enabled"] and report["preferences"] and report["scene_settings"]
    assert report["operators"] == ["bone_map_from_vrm", "delete_gesture", "export_fbx", "extend_scene_end",
                                   "generate_gesture", "save_bone_map", "select_gesture"]
    assert Path(report["module_file"]).is_relative_to(user), "the add-on must run from the installed copy"
    assert list((user / "extensions").rglob("site-packages/threadpoolctl.py")), "the bundled wheel must be installed"
