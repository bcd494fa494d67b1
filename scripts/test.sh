#!/usr/bin/env bash
# Set up a fresh machine and run the whole test suite: the README's second Quick start command,
# and exactly what CI runs (.ci/run). Idempotent: reuses .venv when it is already there, and
# compiles the engine only when it is not already compiled from the current sources (after
# the README's first command, the installation it made is reused: no second 1.5-minute build).
#
# The set-up keeps both cores busy: the compile (mypy, then one long gcc: one core) runs beside
# the install of every dependency and the making of the oracle venvs. pip does not byte-compile
# what it installs (PIP_NO_COMPILE): that was most of its CPU (scipy, matplotlib, dask, ...),
# and Python compiles each module the first time it is imported, which the tests do for a
# small part of those packages. That needs Python to keep what it compiled (__pycache__,
# ignored by git), so PYTHONDONTWRITEBYTECODE is unset here: with it set, every process
# compiled its imports again -- each of the suite's `python -m opspec.cli` subprocesses
# opspec's modules each time (0.7 instead of 0.44 CPU-s for `run --days 1`), every pytest
# process the assertion rewriting of every test module it collects (most of the 20 CPU-s
# a collection of the whole suite takes).
set -euo pipefail
cd "$(dirname "$0")/.."
unset PYTHONDONTWRITEBYTECODE
export PIP_NO_COMPILE=1
bash scripts/system-deps.sh
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
logs="$(mktemp -d)"
tests_tmp=""
trap 'rm -rf "$logs" ${tests_tmp:+"$tests_tmp"}' EXIT
# tests/patterns/test_oracle.py compares with shoobx.wfmc in a test-only venv (never an opspec
# dependency), tests/differential/test_spiff.py with SpiffWorkflow the same way; without them
# (no PyPI) those tests skip saying why. Both are made while opspec installs.
{ bash scripts/oracle-venv.sh \
    || echo "scripts/oracle-venv.sh failed: the oracle tests will be skipped"; } \
    >"$logs/oracle.log" 2>&1 & oracle=$!
{ bash scripts/spiff-venv.sh \
    || echo "scripts/spiff-venv.sh failed: the SpiffWorkflow differential tests will be skipped"; } \
    >"$logs/spiff.log" 2>&1 & spiff=$!
if .venv/bin/python -c 'import sys, opspec._native as n; sys.exit(0 if n._decide()[0] else 1)' \
        2>/dev/null && [ -z "${OPSPEC_PURE_PYTHON:-}" ]; then
    # compiled and current: add the test extras only
    .venv/bin/python scripts/extras.py test | xargs .venv/bin/python -m pip install --quiet
else
    # opspec alone (and the compile, unless OPSPEC_PURE_PYTHON is set or there is no C
    # compiler) in the background; every dependency and test extra meanwhile. They touch
    # different files of .venv: `--no-deps` installs nothing but opspec.
    .venv/bin/python -m pip install --quiet --no-deps -e . >"$logs/build.log" 2>&1 & build=$!
    .venv/bin/python scripts/extras.py --dependencies test \
        | xargs .venv/bin/python -m pip install --quiet
    # While the compile goes on (one core), collect the whole suite once from source on the
    # other, niced so as not to slow the compile: what a first collection writes -- pytest's
    # assertion-rewritten test modules and the bytecode of the dependencies they import (pip
    # compiled none) -- is then read by every pytest process after it, instead of both
    # compiled-pass workers making the same files at once (a collection of the whole suite
    # from cold caches took 30 CPU-s, from warm ones 8). opspec is not installed yet, so it
    # is imported from the checkout and its pytest plugin named (`-p no:opspec`: not twice
    # should the install finish meanwhile). Nothing depends on it succeeding, and it is
    # stopped when the install ends (what it wrote stays: each file is written whole), so it
    # never delays the tests -- on a loaded machine a niced process may have done little.
    PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" OPSPEC_PURE_PYTHON=1 nice -n 19 \
        .venv/bin/python -m pytest --collect-only -q -p no:cacheprovider -p no:opspec \
        -p opspec.testing.plugin >"$logs/warm.log" 2>&1 & warm=$!
    built=0
    wait "$build" || built=$?
    echo "== engine installed at ${SECONDS} s"
    cat "$logs/build.log" >&2
    [ "$built" -eq 0 ] || { echo "installing opspec failed (above)" >&2; exit 1; }
    kill "$warm" 2>/dev/null || true
    wait "$warm" 2>/dev/null || true
fi
.venv/bin/opspec --version
wait "$oracle" "$spiff" || true
cat "$logs/oracle.log" "$logs/spiff.log" >&2
# each phase's start in seconds since this script began, so a CI log shows where time goes
echo "== set up done after ${SECONDS} s"
# The tests' files -- pytest's tmp_path and every temporary folder the code under test and the
# processes it starts make (TMPDIR) -- go to a folder of this run's own on tmpfs (/dev/shm),
# removed when the run ends. On the 2-core CI machine's disk (ext4 mounted with `discard`) an
# fdatasync of a SQLite result store took about 3 ms and an unlink 2-3.5 ms of waiting: the
# interval-coverage test alone (1,000 stores made, closed and deleted) waited about 35 s
# with its core idle; and a pytest process deletes, as it exits, the numbered folders of
# earlier runs in /tmp/pytest-of-$USER beyond the last three (24 s for one that held the
# fresh-venv test's 13,000 files). No test depends on the file system under its temporary
# folder (the full-disk tests inject their ENOSPC). OPSPEC_TEST_TMPDIR=DIR puts the folder
# under DIR instead; empty, the tests keep the system's temporary folder.
tmp_root="${OPSPEC_TEST_TMPDIR-/dev/shm}"
if [ -n "$tmp_root" ] && [ -d "$tmp_root" ] && [ -w "$tmp_root" ] \
        && [ "$(df -Pk "$tmp_root" | awk 'NR == 2 {print $4}')" -ge $((2 * 1024 * 1024)) ]; then
    tests_tmp="$(mktemp -d "$tmp_root/opspec-tests.XXXXXX")"
    export TMPDIR="$tests_tmp"
    echo "== the tests' temporary files in $tests_tmp (removed at the end)"
fi
# Both passes use every core: one pytest-xdist worker more than the cores in the compiled
# pass, two pytest processes side by side in the pass from source. The extra worker fills
# the time a worker waits rather than computes (board runs and device faults on the wall
# clock, browsers, Textual's Pilot, subprocesses starting): on the 2-core machine, the same
# warm clone one after the other, the compiled pass took 4 min 37 s with 3 workers and
# 5 min 53 s with 2 (`-n auto`). OPSPEC_TEST_WORKERS=N (or `-n N` among the arguments, which
# pytest reads last) sets the workers; 0 runs in this process.
cores="$(nproc 2>/dev/null || echo 1)"
workers="${OPSPEC_TEST_WORKERS:-$((cores + 1))}"
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
    # Two folders per pytest process, the two processes side by side.
    pure() {
        OPSPEC_PURE_PYTHON=1 .venv/bin/python -m pytest -q -p no:cacheprovider "$@" \
            >"$logs/${1//\//_}.log" 2>&1
    }
    echo "== pure Python engine: tests/engine tests/conditions tests/patterns tests/behaviour" \
        "(at ${SECONDS} s)"
    pure tests/engine tests/conditions & first=$!
    pure tests/patterns tests/behaviour & second=$!
    failed=0
    wait "$first" || failed=1
    wait "$second" || failed=1
    cat "$logs"/tests_*.log
    if [ "$failed" -ne 0 ]; then
        echo "the pure-Python engine failed (above): the compiled pass does not run" >&2
        exit 1
    fi
    export OPSPEC_REQUIRE_COMPILED=1
fi
echo "== the whole suite, compiled (at ${SECONDS} s)"
# not exec: the trap removes the temporary folder once pytest is done
status=0
.venv/bin/python -m pytest -n "$workers" --dist worksteal "$@" || status=$?
exit "$status"
