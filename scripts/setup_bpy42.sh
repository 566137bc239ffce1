#!/usr/bin/env bash
# Makes .venv-bpy42: Blender 4.2 LTS as a Python module (bpy 4.2.x, Python 3.11), numpy, pytest and the
# threadpoolctl wheel the extension bundles (and pytest-xdist, which runs test files on every core),
# for running the extension's Blender tests on 4.2 as well as 5.0:
#   .venv-bpy42/bin/python -m pytest -q tests/addon -p no:cacheprovider
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv-bpy42/bin/python ]; then
    python -m venv .venv-bpy42
fi
.venv-bpy42/bin/python -m pip install -q "bpy==4.2.*" "numpy>=1.26,<2" "pytest>=8" "pytest-xdist>=3.5" wheels/threadpoolctl-3.8.0-py3-none-any.whl
.venv-bpy42/bin/python -c "import bpy; print('bpy', bpy.app.version_string, 'in .venv-bpy42')"
