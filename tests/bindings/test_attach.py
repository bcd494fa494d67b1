"""`attach_devices`: the API `opspec run` and the walkthrough use to put bound devices into a
run — performers, notes, the wall clock, device callbacks on the engine's thread, the device
report, and every port closed whatever ends the run. The runs here drive
``specs/medication_dispenser.xpdl`` through :class:`Simulation` exactly as ``opspec run`` does,
in wall-clock mode at 20,000x so they take a second or two."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from opspec.bindings import load_profile
from opspec.bindings.attach import AttachedDevices, attach_devices
from opspec.bindings.emulator import Behaviour, EmulatedDevice, PtyEmulator, Reply, SocketEmulator
from opspec.commands._spec import load_any_spec
from opspec.engine.compiled import compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.lanes import user_lane
from opspec.engine.simulation import RunResult, Simulation
from opspec.engine.trace import TraceEvent
from opspec.errors import BindingError
from opspec.request import scripted_user

from .conftest import DATA, DEVICES, _pty_available, needs_pty

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
SPEED = 20000.0
FIRST_DOSE = 36000.0          # 10:00: the 08:00 dose is over, with slack for device replies
SHIPPED = "medication_dispenser"
FAST = "run_dispenser"        # tests/bindings/data: 200 ms reply timeouts, 50 ms reconnects


def _serial_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name.startswith("serial-") and t.is_alive()]


class ButtonPressingDevice(EmulatedDevice):
    """The dispenser board with a user who presses *report* right after each alarm."""

    server: Any = None

    def handle_line(self, line: str) -> list[Any]:
        actions = super().handle_line(line)
        if line.strip() == "ALARM ON" and self.server is not None:
            self.server.send_event("report", after_s=0.002)
        return actions


class ChattyDevice(EmulatedDevice):
    """The dispenser board printing a line no profile knows after dispensing, when no command
    waits (during a command the same line is a garbled reply: see the garbage test)."""

    def handle_line(self, line: str) -> list[Any]:
        actions = super().handle_line(line)
        if line.startswith("DISPENSE"):
            actions.append(Reply(b"HELLO?\n", delay_s=0.002))
        return actions


def _start_board(servers: list[PtyEmulator | SocketEmulator],
                 cls: type[EmulatedDevice] = EmulatedDevice, fault: str = "none",
                 on: str = "pty", profile: str = FAST) -> PtyEmulator | SocketEmulator:
    path = DATA / f"{profile}.toml" if profile == FAST else DEVICES / f"{profile}.toml"
    device = cls(load_profile(path), Behaviour.parse(fault))
    server: PtyEmulator | SocketEmulator = (
        PtyEmulator(device) if on == "pty" else SocketEmulator(device))
    device.server = server  # type: ignore[attr-defined]
    servers.append(server)
    server.start()
    return server


@pytest.fixture
def board() -> Iterator[Any]:
    """``board(cls, fault, on, profile)``: a running emulator, stopped at teardown."""
    servers: list[PtyEmulator | SocketEmulator] = []

    def start(cls: type[EmulatedDevice] = EmulatedDevice, fault: str = "none",
              on: str = "pty", profile: str = FAST) -> PtyEmulator | SocketEmulator:
        return _start_board(servers, cls, fault, on, profile)

    yield start
    for server in servers:
        server.stop()


@dataclass
class Outcome:
    result: RunResult
    report: dict[str, Any]
    notes: list[str]
    wall_clock: bool
    threads: set[int]                 # threads that emitted device events

    def kinds(self) -> list[str]:
        assert self.result.trace is not None
        return [e.kind for e in self.result.trace]

    def faults(self) -> list[dict[str, Any]]:
        assert self.result.trace is not None
        return [dict(e.data or {}) for e in self.result.trace if e.kind == "fault"]

    def fault_path(self) -> list[tuple[str, str]]:
        """(fault, action) of each fault but a reply's timeout that its resend answered.

        The fast profile waits 200 ms (wall) for a reply. On a loaded CI machine the
        emulator's thread was once starved that long before the disconnect: one
        ('timeout', 'retry'), then the disconnect's path exactly as without it. A resend
        answered is the fallback working (tests of the timeout path follow); what the fault
        tests check is the path of the fault they inject, so they read it without those."""
        path = [(f["fault"], f["action"]) for f in self.faults()]
        return [step for step in path if step != ("timeout", "retry")]

    def metric(self, name: str) -> Any:
        return self.result.metrics[name]["total"]


def script(tmp_path: Path, *steps: tuple[str, str]) -> str:
    path = tmp_path / "user.toml"
    body = ",".join(f'["{w}", "{a}"]' for w, a in steps)
    path.write_text(f'otherwise = "complete"\nsteps = [{body}]\n', encoding="utf-8")
    return str(path)


def simulate(bind: list[str], user: str, *, until: float = FIRST_DOSE, spec: Path = SPEC,
             profiles: Path = DATA, settle_s: float | None = None,
             speed: float = SPEED, alone: bool = True) -> Outcome:
    """What ``opspec run --bind`` does, through the public API. ``alone=False``: other
    runs go on beside it (:func:`wall_clock_runs`), whose reader threads may still be
    alive when it ends; the caller checks that none outlives them all."""
    compiled = compile_package(load_any_spec(spec))
    performer, listeners = scripted_user(user, compiled).make(0, 1)
    performers: dict[str, Any] = dict.fromkeys(user_lane(compiled).bind_names, performer)
    threads: set[int] = set()

    def device_thread(event: TraceEvent) -> None:
        if event.kind.startswith("device.") or event.kind == "fault":
            threads.add(threading.get_ident())

    with attach_devices(bind, profiles, settle_s=settle_s) as devices:
        performers.update(devices.performers)
        config = EngineConfig().with_options(realtime=devices.requires_wall_clock,
                                             speed=speed)
        sim = Simulation(compiled, config, performers=performers, seed=1,
                         listeners=[*listeners, device_thread], keep_trace=True)
        devices.install(sim)
        result = sim.run(until=until)
        outcome = Outcome(result, devices.report(), list(devices.notes),
                          devices.requires_wall_clock, threads)
    if alone:
        assert not _serial_threads(), "a reader thread outlived attach_devices"
    return outcome


# ---------------------------------------------------------------------------- the API


def test_attached_devices_give_one_performer_per_participant_and_say_where_they_are(
        ) -> None:
    url = f"emulator://{DATA / f'{FAST}.toml'}"
    with attach_devices([f"alarm:{FAST}={url}", f"dispenser:{FAST}={url}"], DATA) as devices:
        assert isinstance(devices, AttachedDevices)
        assert set(devices.performers) == {"alarm", "dispenser"}
        assert devices.performers["alarm"] is devices.performers["dispenser"]  # one port
        assert devices.notes == [f"alarm, dispenser: bound to {url} ({FAST})"]
        assert devices.requires_wall_clock
        report = devices.report()["alarm, dispenser"]
        assert report["mode"] == {"alarm": "device", "dispenser": "device"}
        assert report["latency_ms"] == {"count": 0, "mean": None, "p99": None, "max": None}
    assert not devices.requires_wall_clock          # closed: nothing left to wait for


def test_auto_without_a_device_is_simulated_needs_no_wall_clock_and_says_so() -> None:
    with attach_devices(["alarm=auto"], DEVICES, ports=[]) as devices:
        assert not devices.requires_wall_clock
        assert any("using the simulated alarm" in note for note in devices.notes)
        assert devices.report()["alarm"]["mode"] == {"alarm": "simulated"}


def test_no_bind_arguments_attach_nothing() -> None:
    with attach_devices([], DEVICES) as devices:
        assert devices.performers == {} and devices.notes == []
        assert not devices.requires_wall_clock and devices.report() == {}


@needs_pty
def test_every_port_is_closed_when_the_run_is_interrupted(board: Any) -> None:
    server = board(on="pty")
    with (pytest.raises(KeyboardInterrupt),
          attach_devices([f"alarm:{FAST}={server.url}"], DATA) as devices):
        binding = devices.performers["alarm"]
        binding.attach(_NullSession())  # type: ignore[arg-type]
        assert _serial_threads()            # the reader is running
        raise KeyboardInterrupt
    assert not _serial_threads()
    assert not binding.requires_wall_clock


@needs_pty
def test_a_port_that_will_not_open_closes_the_ones_already_open(board: Any,
                                                                 tmp_path: Path) -> None:
    # the fast dispenser and the shipped range finder side by side
    for source in (DATA / f"{FAST}.toml", DEVICES / "range_finder.toml"):
        (tmp_path / source.name).write_bytes(source.read_bytes())
    server = board(on="pty")
    with pytest.raises(BindingError, match=r"/dev/opspec-no-such-port.*No such file"):
        attach_devices([f"alarm:{FAST}={server.url}",
                        "range_finder=/dev/opspec-no-such-port"], tmp_path)
    assert not _serial_threads()


class _NullSession:
    now = 0.0

    def trace(self, kind: str, data: Any = None) -> None:
        pass


# ---------------------------------------------------------------------------- runs


@needs_pty
def test_the_button_on_a_pseudo_terminal_reports_and_the_dose_is_taken(
        board: Any, tmp_path: Path) -> None:
    # the shipped profile (500 ms replies, 3 s for the drawer), without the Uno's reset wait
    server = board(ButtonPressingDevice, on="pty", profile=SHIPPED)
    run = simulate([f"alarm={server.url}", f"dispenser={server.url}"],
                   script(tmp_path, ("never", "press_report")), profiles=DEVICES, settle_s=0)
    assert run.wall_clock
    assert run.metric("doses_taken") == 1 and run.metric("doses_missed") == 0
    # The press comes 2 ms (wall) after the board reads ALARM ON; the spec re-alarms after
    # 300 s without a report, 15 ms of wall time at 20,000x. On a loaded machine the press
    # once reached the engine after that (CI: ALARM ON, ALARM ON, DISPENSE 1): the spec's
    # own path for a late report, not a fault. So: one to three alarms, each answered by
    # a press, then the one dispense.
    exchanges = [e.data for e in run.result.trace or () if e.kind == "device.exchange"]
    commands = [x["command"] for x in exchanges]
    alarms = commands.count("ALARM ON")
    assert 1 <= alarms <= 3 and commands == ["ALARM ON"] * alarms + ["DISPENSE 1"]
    assert alarms == run.metric("alarms")
    events = [e.data for e in run.result.trace or () if e.kind == "device.event"]
    assert 1 <= len(events) <= alarms and {x["event"] for x in events} == {"report"}
    assert run.faults() == []
    device = run.report["alarm, dispenser"]
    assert device["latency_ms"]["count"] == len(commands) and device["latency_ms"]["max"] > 0
    assert device["faults"] == []
    # reader-thread lines were handled on the engine's (this) thread
    assert run.threads == {threading.get_ident()}
    assert run.result.summary["drift"]["events"] > 0
    assert run.kinds()[-1] == "run.ended"


def test_the_dose_over_a_loop_url_emulator(tmp_path: Path) -> None:
    url = f"emulator://{DEVICES / f'{SHIPPED}.toml'}"
    run = simulate([f"alarm={url}", f"dispenser={url}"],
                   script(tmp_path, ("after trg_2 30s", "press_report")), profiles=DEVICES)
    assert run.metric("doses_taken") == 1
    assert run.report["alarm, dispenser"]["latency_ms"]["count"] == 2
    assert run.faults() == []


def test_a_socket_that_drops_mid_run_is_reconnected_and_the_dose_is_taken(
        board: Any, tmp_path: Path) -> None:
    server = board(fault="disconnect:1", on="socket")
    # until 11:56: reconnecting takes real time (50 ms here, about 1000 simulated seconds)
    run = simulate([f"alarm:{FAST}={server.url}", f"dispenser:{FAST}={server.url}"],
                   script(tmp_path, ("after trg_2 30s", "press_report")), until=43000)
    assert run.fault_path() == [("disconnected", "reconnect")]
    notes = [e.data["message"] for e in run.result.trace or () if e.kind == "device.note"]
    assert any("reconnected" in note for note in notes)
    assert run.metric("doses_taken") == 1
    assert run.report["alarm, dispenser"]["mode"] == {"alarm": "device", "dispenser": "device"}
    faults = run.report["alarm, dispenser"]["faults"]
    disconnects = [f for f in faults if f["fault"] == "disconnected"]
    assert len(disconnects) == 1 and 28800 <= disconnects[0]["at"] < FIRST_DOSE


@needs_pty
def test_a_vanished_drawer_aborts_the_dispense_along_its_exception_transition(
        board: Any, tmp_path: Path) -> None:
    # the shipped spec: `dispense` --DispenserFault--> record_missed (and the caregiver)
    server = board(fault="disconnect:1", on="pty")
    # until 11:56: closing and reopening the port takes real time (simulated hours here)
    run = simulate([f"alarm:{FAST}={server.url}", f"dispenser:{FAST}={server.url}"],
                   script(tmp_path, ("after trg_2 30s", "press_report")), until=43000)
    assert run.fault_path() == [
        ("disconnected", "reconnect"), ("reconnect-failed", "abort/simulate")]
    device = run.report["alarm, dispenser"]
    assert device["mode"] == {"alarm": "simulated", "dispenser": "aborted"}
    assert run.metric("doses_taken") == 0 and run.metric("doses_missed") == 1
    assert not run.wall_clock                   # the port is gone: nothing real is left
    failed = [e for e in run.result.trace or () if e.kind == "activity.failed"]
    assert [(e.activity, (e.data or {}).get("exception")) for e in failed] == [
        ("dispense", "DispenserFault")]
    assert run.result.summary["instances"]["aborted"] == 0   # handled, not aborted
    assert run.kinds()[-1] == "run.ended"


@needs_pty
def test_a_line_nobody_expects_is_a_named_fault_and_the_run_goes_on(
        board: Any, tmp_path: Path) -> None:
    server = board(ChattyDevice, on="pty", profile=SHIPPED)
    run = simulate([f"alarm={server.url}", f"dispenser={server.url}"],
                   script(tmp_path, ("after trg_2 30s", "press_report")), profiles=DEVICES,
                   settle_s=0)
    assert [(f["fault"], f["action"]) for f in run.faults()] == [("unexpected-line", "none")]
    assert "unexpected line 'HELLO?'" in run.faults()[0]["message"]
    assert run.metric("doses_taken") == 1
    assert run.report["alarm, dispenser"]["mode"] == {"alarm": "device", "dispenser": "device"}


def _misbehaving_alarm(server: PtyEmulator | SocketEmulator, folder: Path) -> Outcome:
    # timeout, hold for a late reply, resend, timeout: 3 x 200 ms (wall) span 3.3 simulated
    # hours at 20,000x, which left too little slack before 12:00 on a busy CI machine; at
    # 8,000x they span 1.3 h and the 08:00 alarm's fallback has 2.6 h (1.2 s wall) to spare
    return simulate([f"alarm:{FAST}={server.url}"],
                    script(folder, ("after trg_2 30s", "press_report")), until=43000,
                    speed=8000.0, alone=False)


def _drawer_fault(folder: Path) -> Outcome:
    # garbage alone ends the attempt at its timeout (3 s wall: a reply may follow noise),
    # 24,000 simulated seconds at 8,000x: the 08:00 dose's fallback comes at about 14:40,
    # 1.6 s (wall) before the run ends at 18:20; the noon dose's DISPENSE waits behind it
    url = f"emulator://{DEVICES / f'{SHIPPED}.toml'}?fault=garbage"
    return simulate([f"dispenser={url}"], script(folder, ("after trg_2 30s", "press_report")),
                    profiles=DEVICES, until=66000.0, speed=8000.0, alone=False)


@pytest.fixture(scope="module")
def wall_clock_runs(tmp_path_factory: pytest.TempPathFactory
                    ) -> dict[str, Outcome | BaseException]:
    """The runs of the tests below that wait on the wall clock (8,000x: 5.4, 5.4 and 8.3 s),
    side by side, each in a thread with its own devices, emulator and script: together they
    take the wall time of the longest, where one after another they held a test worker for
    19 s. Each test reads its own run (a run's error is raised by its test); no serial
    reader thread outlives them."""
    jobs: dict[str, Any] = {"drawer": _drawer_fault}
    servers: list[PtyEmulator | SocketEmulator] = []
    if _pty_available():                        # else the alarm's tests are skipped
        for fault in ("silent", "garbage"):
            server = _start_board(servers, fault=fault, on="pty")
            jobs[fault] = lambda folder, server=server: _misbehaving_alarm(server, folder)
    outcomes: dict[str, Outcome | BaseException] = {}
    # made here, not in the threads: pytest makes its base folder at the first mktemp
    folders = {name: tmp_path_factory.mktemp(name) for name in jobs}

    def run(name: str) -> None:
        try:
            outcomes[name] = jobs[name](folders[name])
        except BaseException as error:  # noqa: BLE001 - raised by the test that reads it
            outcomes[name] = error

    threads = [threading.Thread(target=run, args=(name,), name=f"run-{name}") for name in jobs]
    try:
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        for server in servers:
            server.stop()
    assert not _serial_threads(), "a reader thread outlived attach_devices"
    return outcomes


def _outcome(runs: dict[str, Outcome | BaseException], name: str) -> Outcome:
    found = runs[name]
    if isinstance(found, BaseException):
        raise found
    return found


@needs_pty
@pytest.mark.parametrize(("fault", "named"), [("silent", "timeout"), ("garbage", "garbage")],
                         ids=["no-reply", "garbage"])
def test_a_misbehaving_alarm_retries_then_goes_on_simulated(
        fault: str, named: str, wall_clock_runs: dict[str, Any]) -> None:
    run = _outcome(wall_clock_runs, fault)
    assert [(f["fault"], f["action"]) for f in run.faults()][:2] == [
        (named, "retry"), (named, "simulate")]
    assert run.report["alarm"]["mode"] == {"alarm": "simulated"}
    assert run.metric("doses_taken") == 1        # the simulated alarm kept the dose going
    assert run.kinds()[-1] == "run.ended"


def test_the_clock_of_a_run_depends_on_what_is_bound(board: Any) -> None:
    base = EngineConfig()
    url = f"emulator://{DATA / f'{FAST}.toml'}"
    with attach_devices([f"alarm:{FAST}={url}"], DATA) as devices:
        assert devices.requires_wall_clock and not devices.real_devices
        config, note = devices.clock(base, None, 36000.0)
        # emulators need the wall clock (their replies are wall time) but not 1x
        assert config.realtime and config.speed == 600.0
        assert note is not None and "in-process emulators" in note and "600x" in note
        assert devices.clock(base, 50.0, 36000.0)[0].speed == 50.0
        assert devices.clock(base, None, None)[0].speed == 60.0
    server = board(on="socket")
    with attach_devices([f"alarm:{FAST}={server.url}"], DATA) as devices:
        assert devices.real_devices
        config, note = devices.clock(base, None, 36000.0)
        assert config.realtime and config.speed == 1.0 and note is not None
        assert "a real device is bound" in note
    with attach_devices(["alarm=auto"], DEVICES, ports=[]) as devices:
        assert devices.clock(base, None, 36000.0) == (base, None)
        config, note = devices.clock(base, 5.0, 36000.0)
        assert not config.realtime and note is not None and "has no effect" in note


def test_attach_refuses_a_participant_the_spec_does_not_have() -> None:
    compiled = compile_package(load_any_spec(SPEC))
    with pytest.raises(BindingError, match=r"the spec has no participant 'pump'") as caught:
        attach_devices(["pump=auto"], DEVICES, spec=compiled)
    assert "bindable participants of this spec: alarm, dispenser" in str(caught.value)
    with attach_devices(["alarm=auto"], DEVICES, spec=compiled, ports=[]) as devices:
        assert set(devices.performers) == {"alarm"}


def test_the_shipped_dispenser_profile_and_spec_agree_on_the_drawer_fault(
        wall_clock_runs: dict[str, Any]) -> None:
    # the shipped files, a drawer that answers garbage: DispenserFault is handled by the spec
    profile = load_profile(DEVICES / f"{SHIPPED}.toml")
    fallback = profile.fallback_for("dispenser")
    assert (fallback.then, fallback.exception) == ("abort", "DispenserFault")
    run = _outcome(wall_clock_runs, "drawer")        # the run: _drawer_fault
    failed = [e for e in run.result.trace or () if e.kind == "activity.failed"]
    assert [(e.activity, (e.data or {}).get("exception")) for e in failed] == [
        ("dispense", "DispenserFault")]
    assert run.result.summary["instances"].get("aborted", 0) == 0   # before: aborted 1
    assert run.metric("doses_taken") == 0 and run.metric("doses_missed") == 1
    assert run.result.summary.get("faults") in (None, [])
