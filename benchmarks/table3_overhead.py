"""Table 3 of the source design, measured on this code: workflows & engine vs customised code.

    python benchmarks/table3_overhead.py [--seconds 2000] [--repeat 3]

Two small applications, each activated 10 times a second for ``--seconds`` simulated seconds
and doing the same work (``benchmarks/apps/workload.py``):

- **straight-line**: five steps one after another (``benchmarks/apps/straight.xpdl``);
- **split and join**: one step, three in parallel (AND split), an AND join, one step
  (``benchmarks/apps/splitjoin.xpdl``).

Each runs (a) as a spec through the engine, its steps performed by the same Python functions
bound by Application id, and (b) as hand-written SimPy code calling those functions at the same
simulated times. Every variant runs in its own process; the table shows CPU time
(``time.process_time``, median of ``--repeat``) and peak resident memory (ru_maxrss), side by
side, as the source's Table 3 did. The engine's CPU time excludes loading the spec (the
hand-written code has nothing to load); its RSS includes it (the reader and the model stay
in memory). Both do the same activations (the hand-written timer steps on k * PERIOD, as the
engine's periods do, so float sums do not add one). The machine's load average is printed
before and after: on a shared machine read the overheads as ratios of one run.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

APPS = Path(__file__).resolve().parent / "apps"

ENGINE = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[1])
from workload import STEPS, work
from opspec.engine.builtin_performers import CallablePerformer
from opspec.engine.simulation import Simulation
from opspec.xpdl.loader import load_spec
app, seconds = sys.argv[2], float(sys.argv[3])
package = load_spec(f"{sys.argv[1]}/{app}.xpdl")
performer = CallablePerformer({step: work for step in STEPS[app]})
c0 = time.process_time()
result = Simulation(package, performers={"software": performer}).run(until=seconds)
cpu = time.process_time() - c0
print(json.dumps({"cpu_s": cpu, "rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "activations": result.summary["instances"]["completed"]}))
"""

HANDWRITTEN = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[1])
import simpy
from workload import PERIOD, work
app, seconds = sys.argv[2], float(sys.argv[3])
env = simpy.Environment()
done = [0]

def straight(env):
    for _ in range(5):
        work()
    done[0] += 1
    yield env.timeout(0)

def branch(env):
    work()
    yield env.timeout(0)

def splitjoin(env):
    work()
    yield env.all_of([env.process(branch(env)) for _ in range(3)])
    work()
    done[0] += 1

def timer(env):
    body = straight if app == "straight" else splitjoin
    k = 0
    while True:
        env.process(body(env))
        k += 1
        yield env.timeout(k * PERIOD - env.now)     # on the k * PERIOD grid, no float drift

env.process(timer(env))
c0 = time.process_time()
env.run(until=seconds)
cpu = time.process_time() - c0
print(json.dumps({"cpu_s": cpu, "rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "activations": done[0]}))
"""


def measure(code: str, app: str, seconds: float) -> dict[str, float]:
    out = subprocess.run([sys.executable, "-c", code, str(APPS), app, str(seconds)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2000.0)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    print(f"{args.seconds:g} simulated seconds at 10 Hz; CPU = median of {args.repeat} runs; "
          f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print(f"{'application':<16}{'variant':<24}{'activations':>12}{'CPU s':>9}{'RSS MiB':>9}"
          f"{'CPU overhead':>14}")
    for app, label in (("straight", "straight-line"), ("splitjoin", "split and join")):
        rows = []
        for variant, code in (("workflows & engine", ENGINE), ("customised code", HANDWRITTEN)):
            runs = [measure(code, app, args.seconds) for _ in range(args.repeat)]
            rows.append((variant, runs[0]["activations"],
                         statistics.median(r["cpu_s"] for r in runs),
                         max(r["rss_mib"] for r in runs)))
        base_cpu = rows[1][2]
        for n, (variant, activations, cpu, rss) in enumerate(rows):
            overhead = f"{(cpu / base_cpu - 1) * 100:+.0f} %" if n == 0 else ""
            print(f"{label if n == 0 else '':<16}{variant:<24}{activations:>12}{cpu:>9.2f}"
                  f"{rss:>9.0f}{overhead:>14}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
