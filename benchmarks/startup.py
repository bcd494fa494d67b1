"""Start-up time of the ``opspec`` command, against the interpreter's own start in the same run.

    python benchmarks/startup.py [--repeat 15]

Each command runs in a fresh interpreter (``python -c`` calling ``opspec.cli.main``, so the
console script's own wrapper does not count), interleaved with the baselines round by round so
that a machine drifting in speed hits all of them alike. Printed: the median wall time of each,
its time above ``python -c pass`` (what opspec itself costs), and for reference what importing
NumPy and ``scipy.special`` alone costs -- what every command paid before the commands imported
them only when they need them (``opspec validate`` never does; ``opspec run`` of the dispenser
needs NumPy for its random streams, SciPy not at all).

The commands are the reference scenario's: ``opspec validate`` of the medication dispenser and
``opspec run --days 1`` of it (stochastic user, one simulated day, output discarded).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = str(ROOT / "specs" / "medication_dispenser.xpdl")

MAIN = "import sys; from opspec.cli import main; sys.exit(main(sys.argv[1:]))"

CASES: dict[str, list[str]] = {
    "python -c pass": ["-c", "pass"],
    "import numpy, scipy.special": ["-c", "import numpy, scipy.special"],
    "opspec --version": ["-c", MAIN, "--version"],
    "opspec validate dispenser": ["-c", MAIN, "validate", SPEC],
    "opspec run dispenser --days 1": ["-c", MAIN, "run", SPEC, "--days", "1", "--seed", "1"],
}


def once(args: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, *args], check=True, stdout=subprocess.DEVNULL,
                   cwd=ROOT)
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=15, help="rounds (default 15)")
    args = parser.parse_args(argv)
    from opspec import _native

    print(f"engine: {_native.STATUS}; load average before: "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    times: dict[str, list[float]] = {name: [] for name in CASES}
    for name, case in CASES.items():      # warm the file cache (and .pyc files) once
        once(case)
    for _ in range(args.repeat):
        for name, case in CASES.items():
            times[name].append(once(case))
    base = statistics.median(times["python -c pass"])
    print(f"{'command':32} {'median s':>9} {'above python s':>15} {'x python':>9}")
    for name, values in times.items():
        median = statistics.median(values)
        print(f"{name:32} {median:9.3f} {median - base:15.3f} {median / base:9.2f}")
    print(f"({args.repeat} interleaved rounds; load average after: "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
