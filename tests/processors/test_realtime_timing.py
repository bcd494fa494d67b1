"""Wall-clock mode: ``--timing`` measures wall-clock start lateness (not simulated time), and a
device's answer is placed at the simulated time of its wall-clock arrival, at any --speed.

The assertions follow from what the test itself does on the wall clock (a performer that
blocks the engine's thread for 30 ms, a device thread that answers 10 ms after its offer),
with tolerances of a few ms of wall time, so a busy machine does not make them fail."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any

import pytest
from test_stochastic_cpu import NS

from opspec.engine import wallclock
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.engine.timing import TimingListener
from opspec.xpdl.loader import load_spec


def periodic(tmp_path: Path, period: float) -> Path:
    """A workflow started every ``period`` whose one activity is performed by ``dev``."""
    path = tmp_path / "tick.xpdl"
    path.write_text(
        f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="tick">'
        "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created>"
        '</PackageHeader><Participants><Participant Id="dev"><ParticipantType Type="SYSTEM"/>'
        '</Participant></Participants><Applications><Application Id="act"/></Applications>'
        '<WorkflowProcesses><WorkflowProcess Id="tick"><ProcessHeader/><Activities>'
        '<Activity Id="work"><Implementation><Task><TaskApplication Id="act"/></Task>'
        "</Implementation><Performers><Performer>dev</Performer></Performers></Activity>"
        "</Activities><ExtendedAttributes>"
        f'<ExtendedAttribute Name="opspec:Period" Value="{period}"/>'
        "</ExtendedAttributes></WorkflowProcess></WorkflowProcesses></Package>",
        encoding="utf-8")
    return path


class Device:
    """Answers every work item after ``delay`` wall seconds from a thread of its own; blocks
    the engine's thread for ``block`` wall seconds on the ``block_on``-th offer."""

    def __init__(self, sim_ref: list[Simulation], delay: float = 0.0, block: float = 0.0,
                 block_on: int = -1) -> None:
        self.sim_ref, self.delay, self.block, self.block_on = sim_ref, delay, block, block_on
        self.offers = 0
        self.answers: list[tuple[float, float, Any]] = []   # (offer sim time, post wall, clock)
        self.applications = {"act": self}     # performs Application "act" (registry.py)

    def attach(self, session: Any) -> None:
        self.session = session

    def offer(self, item: Any) -> None:
        offered = self.session.now
        clock = wallclock.active()
        self.offers += 1
        if self.delay <= 0:
            self._slow_step()
            self.session.complete(item)
            return

        def answer() -> None:
            time.sleep(self.delay)
            posted = time.perf_counter()
            self.answers.append((offered, posted, clock))
            self.sim_ref[0].post(lambda: self.session.complete(item))

        threading.Thread(target=answer, daemon=True).start()
        self._slow_step()

    def _slow_step(self) -> None:
        if self.offers == self.block_on:      # the engine's thread is blocked (in I/O, say:
            time.sleep(self.block)            # other threads run meanwhile)

    def withdraw(self, item: Any, reason: str) -> None:
        pass


def test_timing_in_real_time_reports_wall_clock_start_lateness(tmp_path: Path) -> None:
    """A 10 ms periodic workflow for 0.3 s; the 5th offer blocks the engine for 30 ms, so a
    later start runs at least ~20 ms late on the wall clock — the simulated times are exact,
    so a simulated-time jitter would say 0."""
    ref: list[Simulation] = []
    device = Device(ref, block=0.030, block_on=5)
    listener = TimingListener()
    sim = Simulation(load_spec(periodic(tmp_path, 0.01)),
                     EngineConfig(realtime=True, speed=1.0), performers={"dev": device},
                     listeners=[listener])
    ref.append(sim)
    sim.run(until=0.3)
    tick = listener.summary()["tick"]
    assert tick["clock"] == "wall"
    assert tick["started"] >= 29
    assert tick["start_late_max_s"] >= 0.015
    assert tick["jitter_s"] >= 0.015          # max - min start lateness, on the wall clock


@pytest.mark.parametrize("speed", [10.0, 100.0])
def test_a_device_answer_is_placed_at_its_wall_clock_arrival(tmp_path: Path,
                                                               speed: float) -> None:
    """The device answers 10 ms after each offer while the engine's thread is still busy
    for 30 ms with the offer (a slow step): the answer must land at the simulated time of its
    arrival, not when the engine got round to it (20 ms later: 0.2 s simulated at 10x, 2 s at
    100x), nor any later at 100x than at 10x in wall terms."""
    ref: list[Simulation] = []
    device = Device(ref, delay=0.010, block=0.030, block_on=1)
    sim = Simulation(load_spec(periodic(tmp_path, 1.0 * speed)),
                     EngineConfig(realtime=True, speed=speed), performers={"dev": device},
                     keep_trace=True)
    ref.append(sim)
    result = sim.run(until=0.2 * speed)
    done = [e.time for e in result.trace or () if e.kind == "activity.completed"]
    assert device.answers and done
    offered, posted, clock = device.answers[0]
    placed = done[0]
    assert clock is not None
    # where the answer belongs: the simulated time of its arrival on the wall clock
    assert placed == pytest.approx(clock.sim_at(posted), abs=0.003 * speed)
    # and at least the device's 10 ms after the offer
    assert placed - offered >= 0.010 * speed * 0.999


def test_a_wall_clock_run_in_another_thread_leaves_a_simulated_runs_timing_simulated(
        tmp_path: Path) -> None:
    """Two runs in one process (a device run in a thread, a study server's sessions): while
    one runs against the wall clock, the other's --timing is still in simulated time. The
    loop's clock was a module global, which the other thread's timing read as its own."""
    ref: list[Simulation] = []
    inside = threading.Event()

    class Telling(Device):
        def offer(self, item: Any) -> None:
            inside.set()                        # the wall-clock loop is running
            super().offer(item)

    device = Telling(ref)
    wall = Simulation(load_spec(periodic(tmp_path, 0.01)),
                      EngineConfig(realtime=True, speed=1.0), performers={"dev": device})
    ref.append(wall)
    thread = threading.Thread(target=lambda: wall.run(until=1.5), daemon=True)
    thread.start()
    assert inside.wait(10.0)
    ticks = tmp_path / "simulated"          # (periodic writes tick.xpdl in the folder)
    ticks.mkdir()
    listener = TimingListener()

    class Instant:
        """Performs ``act`` at once."""

        def __init__(self) -> None:
            self.applications = {"act": self}

        def attach(self, session: Any) -> None:
            self.session = session

        def offer(self, item: Any) -> None:
            self.session.complete(item)

        def withdraw(self, item: Any, reason: str) -> None:
            pass

    performer = Instant()
    simulated = Simulation(load_spec(periodic(ticks, 2.0)), EngineConfig(),
                           performers={"dev": performer}, listeners=[listener])
    simulated.run(until=20.0)
    running = thread.is_alive()
    thread.join(10.0)
    tick = listener.summary()["tick"]
    assert running                      # the wall-clock run was going on all along
    assert tick["clock"] == "simulated"
    assert tick["response_max_s"] == 0.0      # answered at once, in simulated time
