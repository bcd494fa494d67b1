"""The processor models under load: the vacuum cleaner's periodic workflows (5 Hz sense,
avoid, manoeuvre and arbitrate with CPU demand and deadlines) under each processor model: the
dedicated model, the pooled model with 1-3 workers and 1 or 8 priority levels, and the source's
two engines on 1-2 processors (preemptive: a thread per workflow at fixed priority, as on Linux;
priority-queues: a FIFO queue per priority with its worker and a leader, as on Windows CE),
each with a context-switch cost.

    python benchmarks/processor_models.py [--spec specs/vacuum_cleaner.xpdl] [--seconds 300]
        [--switch-ms 10]

Prints, per configuration and workflow, response times (mean, max), jitter (max - min) and
deadline misses, and the pooled model's context switches: the numbers a designer uses to pick
a processor model (EMWF TR-IIS-08-005, section 4). The dedicated model has one worker per
workflow instance (unlimited processors, by design); its label says how many it used at once.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from opspec.engine.compiled import compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.engine.timing import TimingListener
from opspec.worlds import world_performers
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spec", default=str(ROOT / "specs" / "vacuum_cleaner.xpdl"))
    parser.add_argument("--seconds", type=float, default=300.0)
    parser.add_argument("--switch-ms", type=float, default=10.0)
    args = parser.parse_args(argv)
    compiled = compile_package(open_spec(args.spec))
    configs = [("dedicated", EngineConfig())]
    for workers in (1, 2, 3):
        for priorities in (1, 8):
            configs.append((f"pooled {workers}w {priorities}p", EngineConfig(
                processor_model="pooled", workers=workers, priorities=priorities,
                switch_cost=args.switch_ms / 1000)))
    for model in ("preemptive", "priority-queues"):
        for cpus in (1, 2):
            configs.append((f"{model} {cpus}cpu", EngineConfig(
                processor_model=model, workers=cpus, priorities=8,
                switch_cost=args.switch_ms / 1000)))
    print(f"{Path(args.spec).name}, {args.seconds:g} s simulated, switch cost "
          f"{args.switch_ms:g} ms (all but dedicated); times in ms")
    header = (f"{'model':<22}{'workflow':<12}{'done':>6}{'misses':>7}{'mean':>8}{'max':>8}"
              f"{'jitter':>8}{'switches':>10}")
    print(header)
    print("-" * len(header))
    for label, config in configs:
        timing = TimingListener()
        sim = Simulation(compiled, config, listeners=[timing],
                         performers=world_performers(compiled, seed=0, user=0))
        result = sim.run(until=args.seconds)
        switches = (result.summary.get("pool") or {}).get("switches", "-")
        if "dedicated" in result.summary:
            label = f"dedicated ({result.summary['dedicated']['max_busy']} cpu)"
        for n, (name, t) in enumerate(timing.summary().items()):
            if name in ("battery", "dock", "wander"):
                continue
            print(f"{label if n == 0 else '':<22}{name:<12}{t['completed']:>6}{t['misses']:>7}"
                  f"{(t['response_mean_s'] or 0) * 1e3:>8.1f}"
                  f"{(t['response_max_s'] or 0) * 1e3:>8.1f}{(t['jitter_s'] or 0) * 1e3:>8.1f}"
                  f"{switches if n == 0 else '':>10}")


if __name__ == "__main__":
    main()
