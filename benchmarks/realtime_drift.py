"""Wall-clock drift of a 10 ms periodic workflow in real-time mode, with and without a device.

    python benchmarks/realtime_drift.py [--seconds 5] [--period-ms 10] [--repeat 5]
        [--no-device] [--fifo]

Runs a one-activity workflow started every period (SISARL ``opspec:Period``) at speed 1 for a
few wall-clock seconds through the engine's wall-clock driver, and prints how late events ran
against their wall-clock due time (mean, p50, p99, max, share later than 10 ms) and how far the
simulated clock was behind the wall clock when the run ended. Each repetition runs the engine's
driver as it is (asyncio sleep, then a timed wait, then a short spin: opspec/engine/wallclock.py)
and, interleaved, the baseline of the same driver waking by asyncio timers alone (what it did
before issue 21), with the load average beside each run; the summary gives the spread of p99
over the repetitions. The machine is shared: read the load average.

``--fifo`` runs the whole benchmark under the SCHED_FIFO real-time policy (needs root or
CAP_SYS_NICE): what the driver does when the operating system lets it preempt other work.

Then the same with the activity performed by a device: ``alarm_on`` of the medication
dispenser profile sent to the emulator on a pseudo-terminal through ``attach_devices`` (the
hybrid-time path of ``opspec run --bind``), with the command round trips. Command round-trip
latency alone is measured by ``benchmarks/serial_latency.py``.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

SPEC = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="tick" Name="10 ms tick">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>opspec</Vendor>
    <Created>2026-11-23</Created></PackageHeader>
  <Participants>
    <Participant Id="alarm"><ParticipantType Type="SYSTEM"/></Participant>
  </Participants>
  <Applications><Application Id="alarm_on"/></Applications>
  <WorkflowProcesses>
    <WorkflowProcess Id="tick" Name="tick">
      <ProcessHeader/>
      <Activities>
        <Activity Id="start"><Event><StartEvent/></Event></Activity>
        <Activity Id="sense">{body}</Activity>
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


NO_WORK = "<Implementation><No/></Implementation>"
DEVICE_WORK = ('<Implementation><Task><TaskApplication Id="alarm_on"/></Task></Implementation>'
               "<Performers><Performer>alarm</Performer></Performers>")


def run(period_ms: float, seconds: float, device_url: str | None,
        baseline: bool = False) -> dict[str, Any]:
    from opspec.bindings.attach import attach_devices
    from opspec.engine import wallclock
    from opspec.engine.config import EngineConfig
    from opspec.engine.simulation import Simulation
    from opspec.xpdl.loader import load_spec

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tick.xpdl"
        path.write_text(SPEC.format(period=f"{period_ms / 1000:g}",
                                    body=DEVICE_WORK if device_url else NO_WORK),
                        encoding="utf-8")
        package = load_spec(path)
    binds = [f"alarm={device_url}"] if device_url else []
    saved = wallclock.COARSE_S, wallclock.SPIN_S
    if baseline:                      # wake by asyncio timers alone (before issue 21)
        wallclock.COARSE_S = wallclock.SPIN_S = 0.0
    load = os.getloadavg()[0]
    try:
        with attach_devices(binds, ROOT / "devices", settle_s=0) as devices:
            sim = Simulation(package, EngineConfig(realtime=True, speed=1.0),
                             performers=dict(devices.performers))
            devices.install(sim)
            started = time.perf_counter()
            cpu = time.process_time()
            result = sim.run(until=seconds)
            wall = time.perf_counter() - started
            cpu = time.process_time() - cpu
            report: dict[str, Any] = devices.report()
    finally:
        wallclock.COARSE_S, wallclock.SPIN_S = saved
    drift = result.summary["drift"]
    what = f"device alarm_on over {device_url}" if device_url else "no device"
    label = "baseline (asyncio timers only)" if baseline else "engine"
    print(f"{label}: {period_ms:g} ms periodic workflow, {what}: {seconds:g} s simulated in "
          f"{wall:.3f} s wall (behind by {(wall - seconds) * 1e3:.1f} ms at the end), "
          f"{result.summary['instances'].get('completed', 0)} instances, CPU {cpu:.2f} s, "
          f"load average {load:.2f}")
    print(f"  lateness of {drift['events']} events: mean {drift['mean_s'] * 1e3:.3f} ms, "
          f"p50 {drift['p50_s'] * 1e3:.3f} ms, p99 {drift['p99_s'] * 1e3:.3f} ms, "
          f"max {drift['max_s'] * 1e3:.3f} ms, {drift['late_10ms']} later than 10 ms")
    for name, info in report.items():
        rtt = info["latency_ms"]
        print(f"  device {name}: {rtt['count']} round trips, mean {rtt['mean']} ms, "
              f"p99 {rtt['p99']} ms, max {rtt['max']} ms, {len(info['faults'])} fault(s)")
    return {"p99_ms": drift["p99_s"] * 1e3, "load": load, "cpu_s": cpu}


def spread(label: str, runs: list[dict[str, Any]]) -> None:
    p99 = sorted(r["p99_ms"] for r in runs)
    loads = sorted(r["load"] for r in runs)
    print(f"{label}: p99 lateness over {len(runs)} runs: min {p99[0]:.3f} ms, median "
          f"{p99[len(p99) // 2]:.3f} ms, max {p99[-1]:.3f} ms (load average "
          f"{loads[0]:.2f}-{loads[-1]:.2f}; CPU per run "
          f"{sorted(r['cpu_s'] for r in runs)[len(runs) // 2]:.2f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--period-ms", type=float, default=10.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-device", action="store_true",
                        help="skip the run with the emulated device on a pseudo-terminal")
    parser.add_argument("--fifo", action="store_true",
                        help="run under SCHED_FIFO (needs root or CAP_SYS_NICE)")
    args = parser.parse_args()
    if args.fifo:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))
        print("scheduling policy: SCHED_FIFO, priority 1")
    engine: list[dict[str, Any]] = []
    baseline: list[dict[str, Any]] = []
    for _ in range(args.repeat):
        engine.append(run(args.period_ms, args.seconds, None))
        baseline.append(run(args.period_ms, args.seconds, None, baseline=True))
    spread("engine", engine)
    spread("baseline", baseline)
    if args.no_device or not hasattr(os, "openpty"):
        return
    from opspec.bindings import load_profile
    from opspec.bindings.emulator import EmulatedDevice, PtyEmulator

    profile = load_profile(ROOT / "devices" / "medication_dispenser.toml")
    with PtyEmulator(EmulatedDevice(profile)) as emulator:
        run(args.period_ms, args.seconds, emulator.url)


if __name__ == "__main__":
    main()
