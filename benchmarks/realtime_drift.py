"""Wall-clock drift of a 10 ms periodic workflow in real-time mode, and device round trips.

    python benchmarks/realtime_drift.py [--seconds 5] [--period-ms 10]

Runs a one-activity workflow started every period (SISARL ``opspec:Period``) at speed 1 for a
few wall-clock seconds through the engine's wall-clock driver, and prints how late events ran
against their wall-clock due time (mean, p99, max, share later than 10 ms). Command round-trip
latency over a pseudo-terminal is measured by ``benchmarks/serial_latency.py``.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

SPEC = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="tick" Name="10 ms tick">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>opspec</Vendor>
    <Created>2026-11-23</Created></PackageHeader>
  <WorkflowProcesses>
    <WorkflowProcess Id="tick" Name="tick">
      <ProcessHeader/>
      <Activities>
        <Activity Id="start"><Event><StartEvent/></Event></Activity>
        <Activity Id="sense"><Implementation><No/></Implementation></Activity>
        <Activity Id="end"><Event><EndEvent/></Event></Activity>
      </Activities>
      <Transitions>
        <Transition Id="t1" From="start" To="sense"/>
        <Transition Id="t2" From="sense" To="end"/>
      </Transitions>
      <ExtendedAttributes>
        <ExtendedAttribute Name="opspec:Period" Value="{period}"/>
      </ExtendedAttributes>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--period-ms", type=float, default=10.0)
    args = parser.parse_args()
    from opspec.engine.config import EngineConfig
    from opspec.engine.simulation import Simulation
    from opspec.xpdl.loader import load_spec

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tick.xpdl"
        path.write_text(SPEC.format(period=f"{args.period_ms / 1000:g}"), encoding="utf-8")
        package = load_spec(path)
    sim = Simulation(package, EngineConfig(realtime=True, speed=1.0))
    result = sim.run(until=args.seconds)
    drift = result.summary["drift"]
    print(f"{args.period_ms:g} ms periodic workflow, {args.seconds:g} s of wall-clock time, "
          f"{result.summary['instances'].get('completed', 0)} instances")
    print(f"lateness of {drift['events']} events: mean {drift['mean_s'] * 1e3:.3f} ms, "
          f"p99 {drift['p99_s'] * 1e3:.3f} ms, max {drift['max_s'] * 1e3:.3f} ms, "
          f"{drift['late_10ms']} later than 10 ms")


if __name__ == "__main__":
    main()
