"""periodic-path: a robot-rate spec through the engine beside a bare SimPy loop of its periods.

    python benchmarks/periodic_path.py [--spec specs/vacuum_cleaner.xpdl] [--seconds 3600]
                                       [--rounds 5] [--against CHECKOUT] [--instructions S]

Runs, each in its own process and interleaved round after round (engine, loop, engine, …: the
speed of a shared machine drifts over minutes):

- **engine**: the spec with its world (``SPEC.world.toml``) for ``--seconds`` simulated
  seconds, built through the front hall as ``opspec run`` builds it (the spec is loaded and
  compiled before the clock starts);
- **bare SimPy loop**: one SimPy process per periodic workflow of the spec, each doing
  nothing but ``yield env.timeout(period)`` at that workflow's period and offset — the floor
  of what any executor of those periods pays for its clock.

It prints, per round and as the median, the CPU seconds of each, the events each scheduled
per CPU second (the engine's are every timed callback of the run: periods, CPU demand,
durations, deadlines; the world is stepped when a device is used, not by events of its own;
the loop's are its timeouts) and the ratio of the two CPU times.

``--instructions S`` also counts, under valgrind's callgrind (the same on every run, whatever
the machine's load), the instructions each side executes for ``S`` more simulated seconds
(a run of ``S + 60`` s minus one of 60 s: start-up and loading cancel out) and prints them
per workflow instance and per simulated hour, and their ratio.

``--against CHECKOUT`` also runs, in the same rounds, the engine of another checkout of
opspec (its own compiled modules if it has current ones, else its source; e.g. a
``git worktree`` of main) and prints this engine's CPU over that one's, paired per round:
how much faster a change made the periodic path, measured side by side on a shared machine.
Both must give the same outcome (instances started, the spec's metrics), else the
comparison stops.
Results in docs/engine-performance.md.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

from callgrind import instructions

ROOT = Path(__file__).resolve().parents[1]

_ENGINE = r"""
import json, sys, time
import opspec._native
from opspec.request import RunRequest, prepare
spec, seconds = sys.argv[1], float(sys.argv[2])
prepared = prepare(RunRequest(spec=spec, until=seconds, no_user=True))
run = prepared.build(0)
c0 = time.process_time()
outcome = run.execute()
cpu = time.process_time() - c0
summary = outcome.result.summary
print(json.dumps({"cpu_s": cpu, "events": summary["sim_events"],
                  "instances": summary["instances"]["started"],
                  "outcome": json.dumps(outcome.result.metrics, sort_keys=True),
                  "build": opspec._native.STATUS}))
"""

_LOOP = r"""
import json, sys, time
import simpy
seconds = float(sys.argv[1])
periods = json.loads(sys.argv[2])
env = simpy.Environment()
def periodic(offset, every):
    yield env.timeout(offset)
    while True:
        yield env.timeout(every)
for offset, every in periods:
    env.process(periodic(offset, every))
c0 = time.process_time()
env.run(until=seconds)
cpu = time.process_time() - c0
events = int(repr(env._eid).split("(")[1].rstrip(")"))   # SimPy's event ids handed out
print(json.dumps({"cpu_s": cpu, "events": events}))
"""


def periods(spec: str) -> list[tuple[float, float]]:
    """(offset, period) of every periodic workflow of ``spec`` in its initial mode."""
    from opspec.engine.compiled import compile_package
    from opspec.xpdl.open_spec import open_spec

    compiled = compile_package(open_spec(spec))
    active = compiled.modes.get(compiled.initial_mode or "", None)
    found = []
    for proc in compiled.processes.values():
        trig = proc.start_trigger
        if trig is None or trig.kind != "period" or not trig.every:
            continue
        if active is not None and proc.mode is not None and proc.id not in active:
            continue
        found.append((float(trig.offset), float(trig.every)))
    return found


def _run(code: str, *args: str, checkout: Path | None = None) -> dict[str, Any]:
    env = None
    if checkout is not None:         # that checkout's opspec first on the path
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(
            [str(checkout), *filter(None, [os.environ.get("PYTHONPATH")])])}
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          check=False, cwd=checkout or ROOT, env=env)
    if done.returncode != 0:
        sys.exit(f"benchmark process failed:\n{done.stderr}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def _instruction_ratio(spec: str, seconds: float, found: list[tuple[float, float]]) -> None:
    if shutil.which("valgrind") is None:
        print("\ninstructions: valgrind is not installed (apt-get install valgrind)")
        return
    short, long = 60.0, 60.0 + seconds
    engine = [instructions(_ENGINE, spec, str(t), cwd=ROOT) for t in (short, long)]
    loop = [instructions(_LOOP, str(t), json.dumps(found), cwd=ROOT) for t in (short, long)]
    runs = [_run(_ENGINE, spec, str(t)) for t in (short, long)]
    instances = int(runs[1]["instances"]) - int(runs[0]["instances"])
    e, b = engine[1] - engine[0], loop[1] - loop[0]
    hour = 3600.0 / seconds
    print(f"\ninstructions for {seconds:g} more simulated s (callgrind, {long:g} s - {short:g} s): "
          f"engine {e / 1e9:.2f} x 10^9 ({e / instances / 1000:.1f}k per workflow instance, "
          f"{e * hour / 1e9:.2f} x 10^9 per simulated hour), bare SimPy loop {b / 1e9:.3f} x 10^9 "
          f"({b * hour / 1e9:.2f} x 10^9 per hour); engine / loop {e / b:.1f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spec", default=str(ROOT / "specs" / "vacuum_cleaner.xpdl"))
    parser.add_argument("--seconds", type=float, default=3600.0)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--against", type=Path, default=None, metavar="CHECKOUT",
                        help="also run the engine of this other opspec checkout, interleaved")
    parser.add_argument("--instructions", type=float, default=0.0, metavar="S",
                        help="also count instructions for S more simulated seconds "
                        "(callgrind)")
    args = parser.parse_args()
    spec = str(Path(args.spec).resolve())
    found = periods(spec)
    if not found:
        sys.exit(f"{args.spec} has no periodic workflow in its initial mode")
    engines, loops, others = [], [], []
    for n in range(args.rounds):
        # the order within a round alternates, so neither side always runs first
        first_other = args.against is not None and n % 2 == 1
        if first_other:
            others.append(_run(_ENGINE, spec, str(args.seconds), checkout=args.against))
        engines.append(_run(_ENGINE, spec, str(args.seconds)))
        loops.append(_run(_LOOP, str(args.seconds), json.dumps(found)))
        if args.against is not None and not first_other:
            others.append(_run(_ENGINE, spec, str(args.seconds), checkout=args.against))
    print(f"periodic-path: {Path(spec).name}, {args.seconds:g} simulated s, periods "
          + ", ".join(f"{every:g} s" for _o, every in found) + f"; {args.rounds} rounds")
    print(f"engine: {engines[0]['build']}")
    print(f"{'round':<7}{'engine CPU s':>13}{'events':>9}{'events/s':>11}"
          f"{'loop CPU s':>12}{'events':>9}{'events/s':>11}{'ratio':>8}")
    ratios = []
    for n, (e, b) in enumerate(zip(engines, loops, strict=True), 1):
        e_cpu, b_cpu = float(e["cpu_s"]), float(b["cpu_s"])
        ratios.append(e_cpu / b_cpu)
        print(f"{n:<7}{e_cpu:>13.3f}{e['events']:>9}{int(e['events']) / e_cpu:>11.0f}"
              f"{b_cpu:>12.3f}{b['events']:>9}{int(b['events']) / b_cpu:>11.0f}"
              f"{ratios[-1]:>8.1f}")
    e_med = statistics.median(float(e["cpu_s"]) for e in engines)
    b_med = statistics.median(float(b["cpu_s"]) for b in loops)
    instances = int(engines[0]["instances"])
    print(f"median: engine {e_med:.3f} CPU s ({int(engines[0]['events']) / e_med:,.0f} events/s, "
          f"{instances} workflow instances, {instances / e_med:,.0f} instances/s), "
          f"bare SimPy loop {b_med:.3f} CPU s "
          f"({int(loops[0]['events']) / b_med:,.0f} events/s); engine / loop "
          f"{statistics.median(ratios):.1f}x (paired median)")
    if others:
        _against(args.against, engines, others)
    if args.instructions > 0:
        _instruction_ratio(spec, args.instructions, found)


def _against(checkout: Path, engines: list[dict[str, Any]],
             others: list[dict[str, Any]]) -> None:
    ours = {(e["instances"], e["outcome"]) for e in engines}
    theirs = {(o["instances"], o["outcome"]) for o in others}
    if ours != theirs or len(ours) != 1:
        sys.exit(f"the engine of {checkout} gave another outcome (instances, metrics): "
                 f"{sorted(theirs)} against {sorted(ours)}")
    pairs = [float(e["cpu_s"]) / float(o["cpu_s"]) for e, o in zip(engines, others,
                                                                   strict=True)]
    o_med = statistics.median(float(o["cpu_s"]) for o in others)
    print(f"against {checkout} ({others[0]['build']}): its engine {o_med:.3f} CPU s "
          f"(median); this engine / that one {statistics.median(pairs):.2f}x (paired median; "
          f"pairs {min(pairs):.2f}x-{max(pairs):.2f}x)")


if __name__ == "__main__":
    main()
