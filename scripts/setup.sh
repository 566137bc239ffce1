#!/usr/bin/env bash
# Installs everything the project needs on a fresh Python 3.11 machine:
# the project with bpy 5.0.1, torch 2.13.0 (CPU), scipy, matplotlib, tqdm, threadpoolctl, Ray (the trainer's), pytest, pytest-xdist into the current Python,
# and two virtual environments, .venv-bpy42 and .venv-bpy45, with Blender 4.2 LTS and 4.5 LTS as modules for the
# extension tests.
set -euo pipefail
cd "$(dirname "$0")/.."
python -m pip install -q -e ".[test]"
bash scripts/setup_blender_lts.sh
