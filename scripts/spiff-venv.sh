#!/usr/bin/env bash
# Create .spiff-venv: a test-only virtualenv holding SpiffWorkflow, the maintained Python BPMN
# engine that tests/differential/test_spiff.py runs SpiffWorkflow's own BPMN test files through
# beside opspec (differential testing, issue 32). It is never a dependency of opspec.
# Idempotent and quiet: does nothing when the venv already imports SpiffWorkflow. About 10 s
# with PyPI reachable.
# Usage: bash scripts/spiff-venv.sh [VENV_DIR]   (default: .spiff-venv at the checkout root)
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${1:-.spiff-venv}"
source scripts/test-venv.sh
# 3.x: the version whose test data tests/differential/data/spiff/ holds (README.md there)
test_venv "$venv" "SpiffWorkflow==3.2.0" SpiffWorkflow.bpmn
