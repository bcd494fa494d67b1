"""Evaluation throughput and memory: `opspec evaluate` against the hand-coded baseline.

For each number of users (100 and 1,000 by default; add 10,000 with --large) this runs, each
in its own process so peak memory is measured the same way for both:

- the hand-coded SimPy baseline (``../shared/bench/handcoded_simpy.py``, one process);
- ``opspec evaluate`` of ``specs/medication_dispenser.xpdl`` with its reference user model, on
  1 and on 2 workers (storing results and writing the report, as a user would run it);

and prints simulated user-days per second, the ratio to the baseline measured in the same run,
and peak resident memory (the main process, and the largest worker).

    python benchmarks/evaluation_throughput.py [--days 30] [--users 100 1000] [--large]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
BASELINE = ROOT.parent / "shared" / "bench" / "handcoded_simpy.py"

# Runs one opspec evaluation in a fresh interpreter and reports its peak memory.
_OPSPEC = """
import json, resource, sys, time
from opspec.cli import main
t = time.perf_counter()
status = main(sys.argv[1:] + ["--quiet", "--json"])
wall = time.perf_counter() - t
print(json.dumps({"status": status, "wall_s": wall,
                  "rss_main_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "rss_worker_mib": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024}),
      file=sys.stderr)
"""


def run_baseline(users: int, days: int, seed: int) -> dict[str, float]:
    start = time.perf_counter()
    out = subprocess.run([sys.executable, str(BASELINE), "--users", str(users), "--days",
                          str(days), "--seed", str(seed)], capture_output=True, text=True,
                         check=True, cwd=BASELINE.parent)
    wall = time.perf_counter() - start
    doc = json.loads(out.stdout.strip().splitlines()[-1])
    return {"wall_s": wall, "rss_main_mib": float(doc.get("peak_rss_mib_inproc", 0.0)),
            "miss_pct": float(doc["miss_pct"]), "lat_mean_s": float(doc["lat_mean_s"])}


def run_opspec(users: int, days: int, seed: int, workers: int) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run(
            [sys.executable, "-c", _OPSPEC, "evaluate", str(SPEC), "--users", str(users),
             "--days", str(days), "--seed", str(seed), "--workers", str(workers),
             "--out", str(Path(tmp) / "run")], capture_output=True, text=True, check=True)
    measured = json.loads(out.stderr.strip().splitlines()[-1])
    doc = json.loads(out.stdout)
    measured["miss_pct"] = doc["metrics"]["missed_rate"]["value"] * 100
    measured["lat_mean_s"] = doc["metrics"]["report_latency_s"]["mean"]
    return measured


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--days", type=int, default=30)
    parser.add_argument("--users", type=int, nargs="+", default=[100, 1000])
    parser.add_argument("--large", action="store_true", help="also 10,000 users")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if not BASELINE.is_file():
        sys.exit(f"baseline not found: {BASELINE}")
    sizes = list(args.users) + ([10_000] if args.large else [])
    print(f"dispenser, {args.days} days per user; user-days per second (higher is better), "
          "ratio = opspec / baseline in this run; peak RSS in MiB")
    header = (f"{'users':>6}  {'runner':<18} {'user-days/s':>11} {'ratio':>6} "
              f"{'wall s':>7} {'RSS main':>8} {'RSS worker':>10} {'miss %':>7} {'lat s':>6}")
    print(header)
    print("-" * len(header))
    for users in sizes:
        user_days = users * args.days
        base = run_baseline(users, args.days, args.seed)
        base_rate = user_days / base["wall_s"]
        rows = [("hand-coded SimPy", base, base_rate)]
        for workers in (1, 2):
            result = run_opspec(users, args.days, args.seed, workers)
            rows.append((f"opspec, {workers} worker{'s' if workers > 1 else ''}", result,
                         user_days / result["wall_s"]))
        for name, result, rate in rows:
            worker = result.get("rss_worker_mib")
            print(f"{users:>6}  {name:<18} {rate:>11.0f} {rate / base_rate:>6.2f} "
                  f"{result['wall_s']:>7.2f} {result['rss_main_mib']:>8.0f} "
                  f"{(f'{worker:.0f}' if worker else '-'):>10} {result['miss_pct']:>7.3f} "
                  f"{result['lat_mean_s']:>6.1f}")


if __name__ == "__main__":
    main()
