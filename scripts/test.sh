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
# Both passes use every core: `-n auto` (pytest-xdist) in the compiled pass, two pytest
# processes side by side in the pass from source. OPSPEC_TEST_WORKERS=N (or `-n N` among the
# arguments, which pytest reads last) sets the workers; 0 runs in this process.
workers="${OPSPEC_TEST_WORKERS:-auto}"
if [ -z "${OPSPEC_PURE_PYTHON:-}" ] && command -v cc >/dev/null 2>&1; then
    # The compiled and the pure-Python engine must be one behaviour. What differs between them
    # is only the modules opspec/_native.py lists (all in opspec/engine), so from source run
    # the folders that test the engine itself, construct by construct and error by error:
    # tests/engine, tests/conditions (the compiled condition code against the tree walker),
    # tests/patterns (the workflow patterns, also against the shoobx.wfmc oracle) and
    # tests/behaviour (modes, coordination, the worlds, the robot specs end to end).
    # specs/tests is not re-run from source: its tests are long statistical runs of the
    # shipped specs (robots at 10 ms periods, hundreds of dispenser users) that go along the
    # same engine paths as one run of each spec, and tests/engine/test_native_every_spec.py
    # (compiled pass) runs every spec of specs/ on both engines and requires byte-identical
    # traces -- every event at the same instant from the same random draws -- which no
    # statistic over such runs can tell apart. (It took 150 of the pass's 300 s, loaded.)
    # Two folders per pytest process (the folders' conftest modules share one name, so the
    # pairs are ones that collect together) and the two processes side by side.
    logs="$(mktemp -d)"
    pure() {
        OPSPEC_PURE_PYTHON=1 .venv/bin/python -m pytest -q -p no:cacheprovider "$@" \
            >"$logs/${1//\//_}.log" 2>&1
    }
    echo "== pure Python engine: tests/engine tests/conditions tests/patterns tests/behaviour"
    pure tests/engine tests/conditions & first=$!
    pure tests/patterns tests/behaviour & second=$!
    failed=0
    wait "$first" || failed=1
    wait "$second" || failed=1
    for log in "$logs"/*.log; do cat "$log"; done
    rm -rf "$logs"
    if [ "$failed" -ne 0 ]; then
        echo "the pure-Python engine failed (above): the compiled pass does not run" >&2
        exit 1
    fi
    export OPSPEC_REQUIRE_COMPILED=1
fi
exec .venv/bin/python -m pytest -n "$workers" --dist worksteal "$@"
