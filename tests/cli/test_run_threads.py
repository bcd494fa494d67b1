"""A run's process computes on one core: importing opspec asks numpy's OpenBLAS for one thread,
unless the user set ``OPENBLAS_NUM_THREADS`` themselves.

OpenBLAS starts a server thread per core when numpy is imported, and each spins for about
0.1 CPU-s before it sleeps, even when no BLAS routine is ever called. That CPU was counted in
every run's time and, on a 2-core machine, taken from the run beside it or from the second
evaluation worker (a quarter of an hour of the vacuum cleaner; docs/engine-performance.md).
What is checked is the process's threads at the end of ``opspec run``, not a time."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SPEC = str(ROOT / "specs" / "medication_dispenser.xpdl")

PROBE = """
import contextlib, io, json, os, sys
from opspec.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    status = main(sys.argv[1:])
print(json.dumps({"status": status, "threads": len(os.listdir("/proc/self/task"))}))
"""


def _numpy_uses_openblas() -> bool:
    import numpy

    config = numpy.show_config(mode="dicts")
    return "openblas" in str(config["Build Dependencies"]["blas"].get("name", "")).lower()


pytestmark = [
    pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="counts threads in /proc"),
    pytest.mark.skipif(not _numpy_uses_openblas(), reason="numpy here is not built on OpenBLAS"),
]


def threads_after_a_run(**env: str) -> int:
    environ = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"} | env
    done = subprocess.run([sys.executable, "-c", PROBE, "run", SPEC, "--days", "1", "--seed", "1"],
                          capture_output=True, text=True, cwd=ROOT, env=environ, check=False)
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found["status"] == 0
    return int(found["threads"])


def test_a_run_s_process_has_one_thread():
    assert threads_after_a_run() == 1


def test_the_user_s_own_openblas_thread_count_is_kept():
    assert threads_after_a_run(OPENBLAS_NUM_THREADS="2") == 2
