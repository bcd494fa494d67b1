"""Attach ``--bind`` devices to a run: open the ports, hand the engine its performers, bridge
the device threads into the engine's thread, and say afterwards how the devices did.

Used by ``opspec run`` and ``opspec walkthrough``::

    with attach_devices(args.bind, profiles_dir) as devices:  # BindingError before the run
        performers.update(devices.performers)
        sim = Simulation(compiled, config, performers=performers, ...)
        devices.install(sim)
        result = sim.run(until)              # wall-clock mode when devices.requires_wall_clock
        report = devices.report()

Every port is closed when the block ends, whatever ends it.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Self

from opspec.bindings.bind import bindings_from_args
from opspec.bindings.binding import DeviceBinding
from opspec.bindings.inbox import Inbox
from opspec.bindings.profiles import default_profiles_dir
from opspec.bindings.transport import PortInfo

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledPackage
    from opspec.engine.config import EngineConfig
    from opspec.engine.simulation import Simulation

__all__ = ["AttachedDevices", "attach_devices"]


#: Wall seconds an emulator-only run takes by default (see AttachedDevices.clock).
EMULATOR_RUN_S = 60.0


def _in_process(url: str | None) -> bool:
    return url is not None and url.startswith(("emulator://", "loop://"))


def _ms(value: float) -> float | None:
    return None if math.isnan(value) else round(value * 1e3, 3)


class AttachedDevices:
    """The devices of one run (see the module docstring)."""

    def __init__(self, bindings: Sequence[DeviceBinding], inbox: Inbox) -> None:
        self.bindings = tuple(bindings)
        self.inbox = inbox
        #: participant id → the binding performing it; each binding also serves its profile's
        #: operations by Application id (DeviceBinding.applications).
        self.performers: dict[str, DeviceBinding] = {
            participant: binding for binding in self.bindings
            for participant in binding.participants}
        for binding in self.bindings:   # work handed to the wrong one goes on to its port
            binding.peers = self.performers
        self.notes: list[str] = [note for b in self.bindings for note in b.notes]
        self._sim: Simulation | None = None
        self._reported = False

    @property
    def requires_wall_clock(self) -> bool:
        """Whether a transport is open, so the run must follow the wall clock: the device
        (real or emulated) answers on its own threads, in wall time."""
        return any(b.requires_wall_clock for b in self.bindings)

    @property
    def real_devices(self) -> bool:
        """Whether a transport other than an in-process one (``emulator://``, ``loop://``)
        is open: a device outside opspec, whose timing is its own."""
        return any(b.requires_wall_clock and not _in_process(b.url) for b in self.bindings)

    def clock(self, config: EngineConfig, speed: float | None,
              horizon: float | None) -> tuple[EngineConfig, str | None]:
        """The engine configuration a run with these devices needs, and a line saying why
        (``None``: nothing to say). For a run that is not already in wall-clock mode:

        * a real device: wall clock at ``speed`` (default 1x: the device lives in real time);
        * only in-process emulators: wall clock too, since their replies, late replies,
          timed events and the profile's timeouts happen on their own threads in wall time,
          but not at 1x: at ``speed``, by default fast enough that the run takes about a
          minute (:data:`EMULATOR_RUN_S`), or 60x without a horizon;
        * no transport open (``auto`` fell back to the simulated device): a plain
          simulation, and ``speed`` has no effect (said so).
        """
        if config.realtime:
            return config, None
        if not self.requires_wall_clock:
            if speed is None:
                return config, None
            return config, (f"--speed {speed:g} has no effect: no device port is open (the "
                            "simulated devices run in simulated time), so this is a plain "
                            "simulation; add --realtime to follow the wall clock")
        if self.real_devices:
            chosen = speed if speed is not None else 1.0
            note = "a real device is bound: running on the wall clock"
            if horizon is not None:
                # the default horizon is a day: at 1x, a run that seems to hang for hours
                from opspec.clock import span

                note += (f" at {chosen:g}x, so the run takes {span(horizon / chosen)} of wall "
                         "time (--until or --speed shortens it; Ctrl+C stops it)")
            return config.with_options(realtime=True, speed=chosen), note
        chosen = speed if speed is not None else (
            max(1.0, horizon / EMULATOR_RUN_S) if horizon is not None else 60.0)
        note = ("only in-process emulators are bound: running on the wall clock (their "
                "replies and the profiles' timeouts are wall time)")
        if speed is None:
            note += f", at {chosen:g}x by default (set it with --speed)"
        return config.with_options(realtime=True, speed=chosen), note

    def install(self, sim: Simulation) -> None:
        """Run device callbacks on the engine's thread: every post to the inbox schedules a
        drain through :meth:`Simulation.post` (which also wakes a wall-clock loop early)."""
        self._sim = sim
        inbox = self.inbox

        def drain() -> None:
            inbox.drain()

        inbox.wake = lambda: sim.post(drain)
        if inbox.pending:
            sim.post(drain)

    def report(self) -> dict[str, Any]:
        """Per binding (keyed by its participants, comma-separated): ``profile``, ``url``,
        ``mode`` per participant (``device``/``simulated``/``aborted``), ``latency_ms``
        (``count``, ``mean``, ``p99``, ``max`` of the answered commands' round trips; None
        without any), ``faults`` (``at`` simulated seconds, ``fault``, ``message``,
        ``action``) and ``pending`` (work the device had not finished: see
        :meth:`DeviceBinding.pending`), for the run's summary and JSON.

        The first call also traces each binding's unfinished work as one ``device.pending``
        event (``data``: ``device``, ``port``, ``pending``). It comes after ``run.ended``:
        the engine has no later hook, and the run *has* ended with the work still open."""
        out: dict[str, Any] = {}
        trace = not self._reported
        self._reported = True
        for binding in self.bindings:
            pending = binding.pending()
            if trace and pending:
                binding.trace_pending(pending)
            latency = binding.latency_summary()
            out[", ".join(binding.participants)] = {
                "profile": binding.profile.name, "url": binding.url,
                "mode": {p: binding.mode(p) for p in binding.participants},
                "latency_ms": {"count": latency.count, "mean": _ms(latency.mean),
                               "p99": _ms(latency.p99), "max": _ms(latency.max)},
                "faults": [{k: f.get(k) for k in ("at", "fault", "message", "action")}
                           for f in binding.faults],
                "pending": pending,
            }
        return out

    def close(self) -> None:
        """Close every binding (idempotent). They close side by side: a ``socket://`` port
        takes 0.3 s to close in pySerial, which would add up over several devices."""
        self.inbox.wake = None
        closers = [threading.Thread(target=b.close, name=f"close-{b.profile.name}")
                   for b in self.bindings[1:]]
        for closer in closers:
            closer.start()
        try:
            if self.bindings:
                self.bindings[0].close()
        finally:
            for closer in closers:
                closer.join()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def attach_devices(bind_args: Sequence[str], profiles_dir: str | Path | None = None, *,
                   settle_s: float | None = None,
                   ports: Sequence[PortInfo] | None = None,
                   spec: CompiledPackage | None = None) -> AttachedDevices:
    """Open every ``PARTICIPANT[:PROFILE]=URL`` of ``bind_args`` (profiles from
    ``profiles_dir``, default :func:`default_profiles_dir`). Raises
    :class:`~opspec.errors.BindingError` — with no port left open — for a malformed argument,
    an unknown participant or profile, a participant ``spec`` does not have (when given), or
    an explicit port that cannot be opened."""
    inbox = Inbox()
    folder = Path(profiles_dir) if profiles_dir is not None else default_profiles_dir()
    participants = None if spec is None else {
        p.id for p in spec.package.participants} | {
        p.id for process in spec.package.processes for p in process.participants}
    bindings = bindings_from_args(bind_args, folder, inbox=inbox, settle_s=settle_s,
                                  ports=ports, participants=participants)
    if spec is not None:
        _say_what_runs_by_itself(bindings, spec)
        _say_which_events_nothing_hears(bindings, spec)
    return AttachedDevices(bindings, inbox)


def _say_what_runs_by_itself(bindings: Sequence[DeviceBinding], spec: CompiledPackage) -> None:
    """A note on each binding for the automatic activities of its participants whose
    Application id none of the bound profiles has as an operation. The engine sends an
    automatic activity to a device by its Application id only; without one it runs by itself
    (instantly, or for its duration), so a misspelt ``[operations.alarm_onn]`` looked like a
    device that worked: bound, no fault, and the buzzer never asked."""
    from opspec.engine.compiled import K_TASK
    from opspec.engine.lanes import all_activities

    routed = {op for binding in bindings for op in binding.profile.operations}
    missing: dict[tuple[int, str, str], list[str]] = {}
    for act in all_activities(spec):
        if act.kind != K_TASK or not act.application or act.application in routed:
            continue
        for index, binding in enumerate(bindings):
            if act.participant in binding.participants:
                key = (index, act.participant, act.application)
                missing.setdefault(key, []).append(f"{act.id} in {act.process}")
    for (index, participant, application), where in missing.items():
        profile = bindings[index].profile
        bindings[index].notes.append(
            f"{participant}: application {application!r} ({', '.join(sorted(set(where)))}) "
            f"is not an operation of profile {profile.name}, so it runs by itself, not on "
            f"the device (operations: {', '.join(sorted(profile.operations))})")


def _say_which_events_nothing_hears(bindings: Sequence[DeviceBinding],
                                    spec: CompiledPackage) -> None:
    """A note on each binding whose profile raises a message trigger the spec never names
    (no catch, throw or start event): the device's line, a button press, would be kept a
    while and lost, with nothing saying the profile's ``trigger`` is misspelt."""
    from opspec.engine.lanes import all_activities

    triggers = [t for act in all_activities(spec)
                for t in (act.raises, act.trigger, act.start_trigger, act.end_trigger)]
    for process in spec.processes.values():
        triggers += [process.start_trigger, process.end_trigger,
                     *(t for t, _ in process.start_events)]
    named = {t.name for t in triggers if t is not None and t.name}
    for binding in bindings:
        for event in binding.profile.events.values():
            raised = (event.trigger or "").removeprefix("message:").removeprefix("signal:")
            if raised and raised not in named:
                binding.notes.append(
                    f"{binding.profile.name}: event {event.name!r} raises trigger "
                    f"{event.trigger!r}, which this spec never catches: such lines from the "
                    f"device ({event.line.text!r}) are lost (the spec's triggers: "
                    f"{', '.join(sorted(named)) or 'none'})")
