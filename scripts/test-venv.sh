#!/usr/bin/env bash
# One way to make a test-only virtualenv holding another engine that opspec's differential
# tests run the same files through (shoobx.wfmc, SpiffWorkflow, Prosimos): never a dependency
# of opspec. Sourced by scripts/oracle-venv.sh, spiff-venv.sh and prosimos-venv.sh.
#   test_venv VENV REQUIREMENT IMPORT [PYTHON]
# Idempotent and quiet: does nothing when VENV already imports IMPORT; otherwise makes it with
# PYTHON (default python3) and installs REQUIREMENT from PyPI, then checks the import (a
# non-zero exit status when PyPI cannot be reached: the tests then skip saying why).
test_venv() {
    local venv="$1" requirement="$2" module="$3" python="${4:-python3}" lock
    # Two test processes may ask for the same venv at once (pytest-xdist workers, each in
    # its module's fixture): one makes it while the other waits here, then finds it made.
    # Without the lock the second saw bin/python before pip had installed the engine and
    # ran the driver in a half-made venv (a failed test in a fresh checkout under -n 2).
    mkdir -p "$venv"
    if command -v flock >/dev/null 2>&1; then
        exec {lock}>"$venv/.making"
        flock "$lock"
    fi
    if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c "import $module" >/dev/null 2>&1; then
        return 0
    fi
    "$python" -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --retries 1 \
        --timeout 30 "$requirement" 2>&1 | grep -v "^WARNING: Location" >&2 || true
    "$venv/bin/python" -c "import $module"
}
