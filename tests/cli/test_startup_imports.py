"""Each command imports what it needs when it needs it (issue 31, start-up): checking a spec
loads no numerical library, and running the dispenser loads NumPy (its random streams) but not
SciPy or Matplotlib. What is checked is the set of modules the command's interpreter ended with,
not a time (benchmarks/startup.py measures the time)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SPEC = str(ROOT / "specs" / "medication_dispenser.xpdl")

# Run the command in a fresh interpreter (this one has imported everything the other tests
# needed), then print which of the heavy packages it imported.
PROBE = """
import contextlib, io, json, sys
from opspec.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    status = main(sys.argv[1:])
heavy = sorted({name.split(".")[0] for name in sys.modules} & {"numpy", "scipy", "matplotlib",
               "textual", "simpy", "dask", "jsonschema"})
print(json.dumps({"status": status, "heavy": heavy,
                  "runner": "opspec.engine.activities" in sys.modules}))
"""


def probe(*argv: str) -> dict:
    done = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True,
                          cwd=ROOT, check=False)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def imported(*argv: str) -> tuple[int, list[str]]:
    found = probe(*argv)
    return found["status"], found["heavy"]


def test_validate_imports_no_numpy_scipy_or_matplotlib():
    status, heavy = imported("validate", SPEC)
    assert status == 0
    assert heavy == []


def test_run_of_the_dispenser_imports_numpy_for_its_streams_but_not_scipy():
    status, heavy = imported("run", SPEC, "--days", "1", "--seed", "1")
    assert status == 0
    # the probe sees what was imported; the engine's clock is SimPy's (opspec/engine/clock.py)
    assert "numpy" in heavy and "simpy" in heavy
    assert "scipy" not in heavy and "matplotlib" not in heavy and "textual" not in heavy


def test_validate_of_a_world_spec_builds_its_world_without_the_engine_s_runner():
    """validate builds the world (to refuse a bad one) but runs nothing: the room's devices,
    which subclass the engine's activity runner, are not imported (about 0.1 s of start-up:
    the engine's run state, metrics, processors and plans)."""
    found = probe("validate", str(ROOT / "specs" / "vacuum_cleaner.xpdl"))
    assert found["status"] == 0
    assert found["runner"] is False
