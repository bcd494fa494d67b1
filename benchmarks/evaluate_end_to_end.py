"""`opspec evaluate` end to end against its own simulations and the hand-coded baseline.

On one worker, for N users x D days of the medication dispenser (1,000 x 30 by default), each
in a fresh interpreter:

- **baseline**: the hand-coded SimPy model of the same scenario
  (``../shared/bench/handcoded_simpy.py``);
- **engine alone**: the replications ``opspec evaluate`` runs, and nothing else — every
  user's run of ``opspec.evaluation.replication.run_users`` (spec loaded once, the user model
  drawing, metrics, per-activity counts), results thrown away;
- **end to end**: ``opspec evaluate SPEC --workers 1`` as a user runs it: the same
  replications, the result store (``results.sqlite``), the summaries and the report
  (``report.html`` with its figures).

It prints CPU seconds (user + system of the child process: what the work costs, steady on a
busy machine) and wall seconds, and two ratios measured in this one run: end to end / engine
alone (the overhead of storing and reporting; goal: at most 1.3) and engine alone / baseline
(the cost of executing a specification instead of hand-written code). ``--repeat R`` runs
each R times and keeps the fastest; ``--profile FILE`` also writes a cProfile of one end-to-
end run (``python -m pstats FILE``). The first line says which engine ran (compiled with
mypyc, or from source after an edit): the children import opspec the way ``python -m``
does, from the current folder first, so run it from the checkout whose engine you measure.

    python benchmarks/evaluate_end_to_end.py [--users 1000] [--days 30] [--repeat 1]
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS_TOML = ROOT / "specs" / "medication_dispenser.users.toml"
BASELINE = ROOT.parent / "shared" / "bench" / "handcoded_simpy.py"

# The replications of `opspec evaluate --workers 1`, in the chunks it sends, and nothing else.
_ENGINE = """
import sys
from opspec.evaluation.plan import file_digest
from opspec.evaluation.replication import run_users
from opspec.evaluation.runner import chunks
spec, model, users, days, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
plan = {"designs": [{"label": "A", "spec": spec, "sha256": file_digest(spec)}],
        "users": users, "days": days, "seed": seed, "user_model": model, "engine": {},
        "export": []}
done = 0
for chunk in chunks(list(range(users)), 1):
    done += sum(r.status == "done" for r in run_users(plan, "A", chunk))
assert done == users, done
"""


def _measure(cmd: list[str], cwd: Path | None = None) -> tuple[float, float, str]:
    """(CPU seconds, wall seconds, stdout) of one child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    out = subprocess.run(cmd, check=False, capture_output=True, text=True, cwd=cwd)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode != 0:
        sys.exit(f"failed ({out.returncode}): {' '.join(cmd)}\n{out.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, out.stdout


def baseline(users: int, days: int, seed: int) -> tuple[float, float]:
    cpu, wall, _ = _measure([sys.executable, str(BASELINE), "--users", str(users), "--days",
                             str(days), "--seed", str(seed)], cwd=BASELINE.parent)
    return cpu, wall


def engine_alone(users: int, days: int, seed: int) -> tuple[float, float]:
    cpu, wall, _ = _measure([sys.executable, "-c", _ENGINE, str(SPEC), str(USERS_TOML),
                             str(users), str(days), str(seed)])
    return cpu, wall


def end_to_end(users: int, days: int, seed: int, profile: str | None = None
               ) -> tuple[float, float]:
    with tempfile.TemporaryDirectory() as tmp:
        run = [sys.executable] + (["-m", "cProfile", "-o", profile] if profile else []) + [
            "-m", "opspec", "evaluate", str(SPEC), "--users", str(users), "--days",
            str(days), "--seed", str(seed), "--workers", "1", "--user-model",
            str(USERS_TOML), "--quiet", "--json", "--out", str(Path(tmp) / "run")]
        cpu, wall, out = _measure(run)
        doc = json.loads(out)
        assert doc["metrics"]["doses_due"]["users"] == users
        assert (Path(tmp) / "run" / "report.html").is_file()
    return cpu, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--users", type=int, default=1000)
    parser.add_argument("--days", type=int, default=30)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=1,
                        help="runs of each; the fastest counts (default 1)")
    parser.add_argument("--profile", metavar="FILE",
                        help="also write a cProfile of one end-to-end run to FILE")
    args = parser.parse_args()
    if not BASELINE.is_file():
        sys.exit(f"baseline not found: {BASELINE}")
    runners = {"baseline (hand-coded SimPy)": baseline, "engine alone": engine_alone,
               "opspec evaluate, end to end": end_to_end}
    best: dict[str, tuple[float, float]] = {}
    paired: list[float] = []        # end to end / engine alone (CPU) within each round
    for _ in range(max(1, args.repeat)):
        this: dict[str, float] = {}
        for name, runner in runners.items():      # interleaved: load drifts hit all alike
            cpu, wall = runner(args.users, args.days, args.seed)
            this[name] = cpu
            old = best.get(name)
            best[name] = (min(cpu, old[0]), min(wall, old[1])) if old else (cpu, wall)
        paired.append(this["opspec evaluate, end to end"] / this["engine alone"])
    _, _, version = _measure([sys.executable, "-m", "opspec", "--version"])
    print(" ".join(version.split()))
    print(f"medication dispenser, {args.users:,} users x {args.days} days, one worker, "
          f"fastest of {max(1, args.repeat)}")
    print(f"{'':<30}{'CPU s':>8}{'wall s':>9}")
    for name, (cpu, wall) in best.items():
        print(f"{name:<30}{cpu:>8.2f}{wall:>9.2f}")
    base, engine, e2e = best.values()
    print(f"end to end / engine alone: {e2e[0] / engine[0]:.2f} (CPU), "
          f"{e2e[1] / engine[1]:.2f} (wall); goal <= 1.3")
    print(f"engine alone / baseline:   {engine[0] / base[0]:.2f} (CPU), "
          f"{engine[1] / base[1]:.2f} (wall)")
    if len(paired) > 1:     # on a machine whose speed drifts, the fastest runs may not pair
        print(f"end to end / engine alone within each round (CPU): median "
              f"{statistics.median(paired):.2f}, range {min(paired):.2f}-{max(paired):.2f}")
    if args.profile:
        end_to_end(args.users, args.days, args.seed, profile=args.profile)
        print(f"profile of one end-to-end run: {args.profile} (python -m pstats)")


if __name__ == "__main__":
    main()
