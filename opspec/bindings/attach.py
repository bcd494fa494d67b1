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
    from opspec.engine.simulation import Simulation

__all__ = ["AttachedDevices", "attach_devices"]


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
        self.notes: list[str] = [note for b in self.bindings for note in b.notes]
        self._sim: Simulation | None = None

    @property
    def requires_wall_clock(self) -> bool:
        """Whether a real transport is open, so the run must follow the wall clock."""
        return any(b.requires_wall_clock for b in self.bindings)

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
        without any) and ``faults`` (``at`` simulated seconds, ``fault``, ``message``,
        ``action``), for the run's summary and JSON."""
        out: dict[str, Any] = {}
        for binding in self.bindings:
            latency = binding.latency_summary()
            out[", ".join(binding.participants)] = {
                "profile": binding.profile.name, "url": binding.url,
                "mode": {p: binding.mode(p) for p in binding.participants},
                "latency_ms": {"count": latency.count, "mean": _ms(latency.mean),
                               "p99": _ms(latency.p99), "max": _ms(latency.max)},
                "faults": [{k: f.get(k) for k in ("at", "fault", "message", "action")}
                           for f in binding.faults],
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
                   ports: Sequence[PortInfo] | None = None) -> AttachedDevices:
    """Open every ``PARTICIPANT[:PROFILE]=URL`` of ``bind_args`` (profiles from
    ``profiles_dir``, default :func:`default_profiles_dir`). Raises
    :class:`~opspec.errors.BindingError` — with no port left open — for a malformed argument,
    an unknown participant or profile, or an explicit port that cannot be opened."""
    inbox = Inbox()
    folder = Path(profiles_dir) if profiles_dir is not None else default_profiles_dir()
    bindings = bindings_from_args(bind_args, folder, inbox=inbox, settle_s=settle_s,
                                  ports=ports)
    return AttachedDevices(bindings, inbox)
