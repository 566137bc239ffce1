#!/usr/bin/env bash
# Makes .venv-bpy42 and .venv-bpy45: Blender 4.2 LTS and 4.5 LTS as Python modules (bpy 4.2.x / 4.5.x,
# Python 3.11), numpy, pytest, pytest-xdist and the threadpoolctl wheel the extension bundles, for running
# the extension's Blender tests on the LTS releases as well as on 5.0:
#   .venv-bpy45/bin/python -m pytest -q tests/addon -p no:cacheprovider
# `bash scripts/setup_blender_lts.sh 4.5` makes only that one.
set -euo pipefail
cd "$(dirname "$0")/.."
versions=("$@")
[ ${#versions[@]} -gt 0 ] || versions=(4.2 4.5)
for version in "${versions[@]}"; do
    venv=".venv-bpy${version/./}"
    if [ ! -x "$venv/bin/python" ]; then
        python -m venv "$venv"
    fi
    "$venv/bin/python" -m pip install -q "bpy==$version.*" "numpy>=1.26,<2" "pytest>=8" "pytest-xdist>=3.5" \
        wheels/threadpoolctl-3.8.0-py3-none-any.whl
    "$venv/bin/python" -c "import bpy; print('bpy', bpy.app.version_string, 'in $venv')"
done
