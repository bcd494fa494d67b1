#!/usr/bin/env bash
# Set up a fresh machine and run the whole test suite: the README's second Quick start command,
# and exactly what CI runs (.ci/run). Idempotent: reuses .venv when it is already there.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/system-deps.sh
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet -e '.[test]'
.venv/bin/opspec --version
# tests/patterns/test_oracle.py compares with shoobx.wfmc in a test-only venv (never an opspec
# dependency); without it (no PyPI) those tests skip saying why.
bash scripts/oracle-venv.sh || echo "scripts/oracle-venv.sh failed: the oracle tests will be skipped" >&2
# With a C compiler the install compiles the engine (setup.py); a test checks that it did.
if [ -z "${OPSPEC_PURE_PYTHON:-}" ] && command -v cc >/dev/null 2>&1; then
    export OPSPEC_REQUIRE_COMPILED=1
fi
exec .venv/bin/python -m pytest "$@"
