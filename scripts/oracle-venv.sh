#!/usr/bin/env bash
# Create .oracle-venv: a test-only virtualenv holding shoobx.wfmc, the reference Python XPDL
# engine that tests/patterns/test_oracle.py runs the same XPDL files through (differential
# testing, issue 16). It is never a dependency of opspec. Idempotent and quiet: does nothing
# when the venv already imports shoobx.wfmc. About 10 s with PyPI reachable.
# Usage: bash scripts/oracle-venv.sh [VENV_DIR]   (default: .oracle-venv at the checkout root)
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${1:-.oracle-venv}"
source scripts/test-venv.sh
test_venv "$venv" "shoobx.wfmc>=4.3,<5" shoobx.wfmc
