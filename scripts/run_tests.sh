#!/usr/bin/env bash
# The project's test command: the linter and the type checker (ruff and mypy, configured in pyproject.toml),
# then the whole suite on Blender 5.0 (bpy 5.0.1), then the Blender-facing extension tests again on Blender
# 4.5 LTS and 4.2 LTS from the environments made by scripts/setup.sh. Test files run in parallel, one per
# core (pytest-xdist; a file's module fixtures are built once); PYTEST_WORKERS=0 runs them in this one process.
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== ruff =="
python -m ruff check .
echo "== mypy =="
python -m mypy
PARALLEL=(-n "${PYTEST_WORKERS:-auto}" --dist loadfile)
python -m pytest -q "${PARALLEL[@]}" "$@"
# Blender 4.x as a module can crash (a segfault in create_bones) in its glTF importer once other
# extension tests have run in the same process, so each file that imports glTF runs in a process of its own.
OWN_PROCESS=(tests/addon/test_rig_variants.py tests/addon/test_real_rigs.py tests/addon/test_real_finger.py
             tests/addon/test_vrm_characters.py tests/addon/test_hostile_vrm_and_paths.py)
for version in 45 42; do
    venv=".venv-bpy$version"
    if [ ! -x "$venv/bin/python" ]; then
        echo "scripts/run_tests.sh: $venv is missing; run scripts/setup.sh to test Blender ${version:0:1}.${version:1} too" >&2
        exit 1
    fi
    echo "== Blender ${version:0:1}.${version:1} LTS: extension tests =="
    "$venv/bin/python" -m pytest -q "${PARALLEL[@]}" tests/addon -p no:cacheprovider "${OWN_PROCESS[@]/#/--ignore=}"
    for test_file in "${OWN_PROCESS[@]}"; do
        "$venv/bin/python" -m pytest -q "$test_file" -p no:cacheprovider
    done
done
