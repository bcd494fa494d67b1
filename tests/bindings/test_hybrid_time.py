"""Hybrid time: in wall-clock mode a device's answer is placed on the simulated timeline at the
time that corresponds to the wall clock when it arrived, not at the time of the engine's last
event. The assertions are lower bounds that follow from the device's own delay (a reply that
takes 150 ms of wall time at 20,000x cannot land before 3,000 simulated seconds have passed),
so a slow machine cannot make them fail."""

from __future__ import annotations

import threading
import time
from pathlib import Path

from opspec.commands._spec import load_any_spec
from opspec.engine.compiled import compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation

from .conftest import DEVICES
from .test_attach import SHIPPED, SPEC, SPEED, script, simulate

ALARM_AT = 8 * 3600.0            # the 08:00 dose's alarm
LATE_S = 0.150                   # the emulated board answers every command 150 ms late


def test_a_callback_posted_from_a_device_thread_runs_at_the_wall_clock_time() -> None:
    compiled = compile_package(load_any_spec(SPEC))
    sim = Simulation(compiled, EngineConfig().with_options(realtime=True, speed=100.0), seed=0)
    seen: list[float] = []
    posted_after = threading.Event()

    def device() -> None:
        while sim.wake is None:             # the wall-clock loop has started
            time.sleep(0.001)
        time.sleep(0.2)                     # 0.2 s of wall time = 20 simulated s at 100x
        sim.post(lambda: seen.append(float(sim.env.now)))
        posted_after.set()

    threading.Thread(target=device, daemon=True).start()
    sim.run(until=60.0)
    assert posted_after.is_set() and len(seen) == 1
    # (the loop notes its wall-clock start just after it announces itself: 1 s of slack)
    assert 19.0 <= seen[0] <= 60.0          # was 0.0: the time of the last engine event


def test_a_late_device_answer_completes_the_alarm_when_it_arrives(tmp_path: Path) -> None:
    url = f"emulator://{DEVICES / f'{SHIPPED}.toml'}?fault=late:{LATE_S * 1000:g}"
    outcome = simulate([f"alarm:{SHIPPED}={url}"], script(tmp_path), profiles=DEVICES,
                       until=ALARM_AT + 3 * LATE_S * SPEED)
    assert outcome.wall_clock
    trace = outcome.result.trace
    assert trace is not None
    exchanges = [e for e in trace if e.kind == "device.exchange"]
    assert exchanges and exchanges[0].data["command"] == "ALARM ON"
    first = exchanges[0]
    latency = first.data["latency"]
    assert latency >= LATE_S
    # sent at 08:00 (or later, if the engine ran late); answered latency × speed after that
    assert first.time >= ALARM_AT + latency * SPEED * 0.999
    # the alarm's activity completes (and the user hears it) no earlier than the answer
    done = [e for e in trace if e.kind == "activity.completed"
            and e.activity == "sound_alarm"]
    assert done and done[0].time >= first.time
    raised = [e for e in trace if e.kind == "trigger.raised" and e.time >= ALARM_AT]
    assert raised and raised[0].time >= first.time
    # the report agrees with the trace: no fault, one answered command of ≥ 150 ms
    report = outcome.report["alarm"]
    assert report["faults"] == []
    assert report["latency_ms"]["count"] >= 1 and report["latency_ms"]["max"] >= 150.0
