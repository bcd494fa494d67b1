#!/usr/bin/env bash
# Set up a fresh machine and run the whole test suite: the README's second Quick start command,
# and exactly what CI runs (.ci/run). Idempotent: reuses .venv when it is already there, and
# compiles the engine only when it is not already compiled from the current sources (after
# the README's first command, the installation it made is reused: no second 1.5-minute build).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/system-deps.sh
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
if .venv/bin/python -c 'import sys, opspec._native as n; sys.exit(0 if n._decide()[0] else 1)' \
        2>/dev/null && [ -z "${OPSPEC_PURE_PYTHON:-}" ]; then
    # compiled and current: add the test extras only
    .venv/bin/python scripts/extras.py test | xargs .venv/bin/python -m pip install --quiet
else
    .venv/bin/python -m pip install --quiet -e '.[test]'
fi
.venv/bin/opspec --version
# tests/patterns/test_oracle.py compares with shoobx.wfmc in a test-only venv (never an opspec
# dependency); without it (no PyPI) those tests skip saying why.
bash scripts/oracle-venv.sh || echo "scripts/oracle-venv.sh failed: the oracle tests will be skipped" >&2
# tests/differential/test_spiff.py: SpiffWorkflow, the same way (a test-only venv)
bash scripts/spiff-venv.sh || echo "scripts/spiff-venv.sh failed: the SpiffWorkflow differential tests will be skipped" >&2
if [ -z "${OPSPEC_PURE_PYTHON:-}" ] && command -v cc >/dev/null 2>&1; then
    # The compiled and the pure-Python engine must be one behaviour: the tests that run the
    # engine also run from source (one folder per call: folders share the module name
    # `conftest`). Then the whole suite runs compiled; a test checks that it is.
    for folder in tests/engine tests/patterns tests/behaviour specs/tests tests/conditions; do
        echo "== pure Python engine: $folder"
        OPSPEC_PURE_PYTHON=1 .venv/bin/python -m pytest -q -p no:cacheprovider "$folder"
    done
    export OPSPEC_REQUIRE_COMPILED=1
fi
exec .venv/bin/python -m pytest "$@"
