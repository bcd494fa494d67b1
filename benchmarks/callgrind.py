"""Instructions a Python snippet executes, counted by valgrind's callgrind: the steady measure
the benchmarks print beside CPU time, which swings on a shared machine.

Imported by the benchmark scripts beside it (``python benchmarks/NAME.py`` puts this folder
first on ``sys.path``).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path


def instructions(code: str, *args: str, cwd: Path) -> int:
    """Instructions executed by ``python -c code args`` under callgrind (exits the benchmark
    with callgrind's own output when the run fails)."""
    # one OpenBLAS thread: numpy's server threads otherwise spin for a varying number of
    # instructions that callgrind counts with the run's (about 2.5M a run of the robot specs);
    # fixed string hashes and no address-space randomisation (``setarch -R``, where the
    # system allows it): dictionaries and sets keyed by strings or objects otherwise collide
    # differently from run to run, and N -> 2N differences moved by up to 13k a dose cycle
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    env.setdefault("PYTHONHASHSEED", "0")
    command = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
               sys.executable, "-c", code, *args]
    found = None
    for prefix in ((["setarch", "-R"],) if shutil.which("setarch") else ()) + ([],):
        done = subprocess.run([*prefix, *command], capture_output=True, text=True,
                              check=False, cwd=cwd, env=env)
        found = re.search(r"Collected : (\d+)", done.stderr)
        if done.returncode == 0 and found is not None:
            break
    if done.returncode != 0 or found is None:
        sys.exit(f"callgrind run failed:\n{done.stderr[-2000:]}")
    return int(found.group(1))
