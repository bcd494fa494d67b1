#!/usr/bin/env bash
# Create .prosimos-venv: a test-only virtualenv holding Prosimos (PyPI `prosimos`), the
# business-process simulator of the University of Tartu that reads BIMP/QBP-style models, which
# tests/bpmn/test_prosimos_side_by_side.py runs the same model through (differential testing,
# issue 28). It is never a dependency of opspec. Idempotent and quiet: does nothing when the
# venv already imports prosimos. Prosimos needs Python 3.9-3.11.
# Usage: bash scripts/prosimos-venv.sh [VENV_DIR]   (default: .prosimos-venv at the checkout root)
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${1:-.prosimos-venv}"
source scripts/test-venv.sh
if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c "import prosimos.simulation_engine" >/dev/null 2>&1; then
    exit 0
fi
python="${PROSIMOS_PYTHON:-python3}"
if ! "$python" -c 'import sys; sys.exit(0 if (3, 9) <= sys.version_info[:2] <= (3, 11) else 1)'; then
    echo "Prosimos needs Python 3.9 to 3.11; $("$python" --version 2>&1) found (set PROSIMOS_PYTHON)" >&2
    exit 1
fi
test_venv "$venv" "prosimos>=2.0,<3" prosimos.simulation_engine "$python"
