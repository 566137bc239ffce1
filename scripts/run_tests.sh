#!/usr/bin/env bash
# The project's test command: the whole suite on Blender 5.0 (bpy 5.0.1), then the Blender-facing
# extension tests again on Blender 4.2 LTS from the second environment made by scripts/setup.sh.
# Test files run in parallel, one per core (pytest-xdist; a file's module fixtures are built once);
# PYTEST_WORKERS=0 runs them in this one process.
set -euo pipefail
cd "$(dirname "$0")/.."
PARALLEL=(-n "${PYTEST_WORKERS:-auto}" --dist loadfile)
python -m pytest -q "${PARALLEL[@]}" "$@"
if [ -x .venv-bpy42/bin/python ]; then
    echo "== Blender 4.2 LTS: extension tests =="
    # Blender 4.2 as a module can crash (a segfault in create_bones) in its glTF importer once other
    # extension tests have run in the same process, so each file that imports glTF runs in a process
    # of its own.
    OWN_PROCESS=(tests/addon/test_rig_variants.py tests/addon/test_real_rigs.py tests/addon/test_real_finger.py
                 tests/addon/test_vrm_characters.py)
    .venv-bpy42/bin/python -m pytest -q "${PARALLEL[@]}" tests/addon -p no:cacheprovider \
        "${OWN_PROCESS[@]/#/--ignore=}"
    for test_file in "${OWN_PROCESS[@]}"; do
        .venv-bpy42/bin/python -m pytest -q "$test_file" -p no:cacheprovider
    done
else
    echo "scripts/run_tests.sh: .venv-bpy42 is missing; run scripts/setup.sh to test Blender 4.2 too" >&2
    exit 1
fi
