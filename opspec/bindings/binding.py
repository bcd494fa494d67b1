"""DeviceBinding: a Performer whose work is done by a serial device speaking a profile's
line protocol, with the profile's fallback when the device misbehaves.

Threads. pySerial's reader thread and the reply timers never touch the engine: they post
callbacks into the binding's :class:`~opspec.bindings.inbox.Inbox`, which the engine drains
on its own thread. Every method of the binding runs on that engine thread, except where a
docstring says otherwise, so the binding's state needs no locks.

This module holds the performer's face (offer, withdraw, attach, pending, close); the parts
behind it are mixins in modules of their own: the state they share and the reporting of
faults and notes (:mod:`~opspec.bindings.binding_state`), the line protocol
(:mod:`~opspec.bindings.exchanges`), the port's reader and its reconnection
(:mod:`~opspec.bindings.reconnection`) and the profile's fallback
(:mod:`~opspec.bindings.fallback`).

Faults are trace events of kind :data:`~opspec.engine.trace.EventKind.FAULT` whose ``data``
names the fault (``fault``: ``timeout``, ``garbage``, ``unexpected-line``, ``late-reply``,
``disconnected``, ``reconnect-failed``, ``unavailable``, ``unknown-operation``,
``missing-data``, ``device-error``: a declared error reply such as ``ERR JAM``) and the
``action`` taken (``retry``, ``reconnect``, ``simulate``, ``abort``, ``exception``, ``none``). Each exchange is a ``device.exchange`` event carrying its round-trip ``latency``
in seconds; notes (bound, switched to simulated, reconnected) are ``device.note`` events.

Noise during a command (a debug line the profile does not ignore, a partial or garbled
frame) does not end the command's attempt: a command such as ``DISPENSE`` may have been
carried out, and retrying it or applying the fallback (a dose recorded as missed) on the
first stray line would lose the reply that follows. The attempt waits for its reply until
its timeout: a reply after noise is read (the noise reported as a fault, action ``none``);
noise and no reply is ``garbage`` at the timeout, then the retry or the fallback.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Self

import serial

from opspec.bindings.binding_state import (
    DEVICE_EVENT,
    DEVICE_EXCHANGE,
    DEVICE_NOTE,
    DEVICE_PENDING,
    Connection,
    Job,
    Mode,
)
from opspec.bindings.exchanges import Exchanges
from opspec.bindings.fallback import Fallback
from opspec.bindings.latency import LatencySummary, summarise
from opspec.bindings.reconnection import Reconnection
from opspec.bindings.templates import TemplateError
from opspec.engine.performers import PerformerSession, WorkItem

__all__ = ["DEVICE_EVENT", "DEVICE_EXCHANGE", "DEVICE_NOTE", "DEVICE_PENDING", "Connection",
           "DeviceBinding", "Mode"]


class DeviceBinding(Exchanges, Reconnection, Fallback):
    """Performs the work items of ``participants`` on a device (or on its simulation).

    Build it with :func:`opspec.bindings.bind`; ``port`` is an already open pySerial port
    (``None``: simulated from the start, with ``notes`` saying why). Call :meth:`close` when
    the run ends. ``inbox`` must be drained by the engine's loop (shared by all bindings of a
    run is fine).
    """

    # ------------------------------------------------------------------ public
    @property
    def applications(self) -> dict[str, None]:
        """The profile's operations: the engine routes automatic activities whose Application
        id names one of them to this binding (see PerformerRegistry.bind)."""
        return dict.fromkeys(self.profile.operations)

    @property
    def simulated(self) -> bool:
        """Whether every participant is served by the simulated device now."""
        return all(mode == "simulated" for mode in self._modes.values())

    @property
    def requires_wall_clock(self) -> bool:
        """Whether a real transport is (still) in use, so the run must follow wall time."""
        return self._connection in ("open", "reconnecting")

    def latency_summary(self) -> LatencySummary:
        return summarise(self.latencies)

    def pending(self) -> list[dict[str, Any]]:
        """The device work not finished yet (asked at the run's end): each entry has
        ``state`` (``sent``: a command awaits its reply; ``held``: a retry waits out the
        late-reply window; ``queued``; ``awaiting-event``: a passive operation;
        ``reconnecting``: the port is being reopened), ``message``, and for work items
        ``participant``, ``activity``, ``instance`` and ``command``."""
        out: list[dict[str, Any]] = []
        if self._connection == "reconnecting":
            out.append({"state": "reconnecting", "message":
                        f"{self._label()}: still reconnecting to {self.url}"})

        def entry(state: str, item: WorkItem, line: str | None, what: str) -> None:
            out.append({"state": state, "participant": item.participant,
                        "activity": item.activity, "instance": item.instance, "command": line,
                        "message": f"{self._who(item)}: {item.activity} (instance "
                                   f"{item.instance}) {what}"})

        job = self._inflight
        if job is not None and not job.withdrawn:
            entry("sent", job.item, job.line, f"sent {job.line!r}, no reply yet "
                  f"(attempt {job.attempts})")
        if self._resend is not None and not self._resend.withdrawn:
            entry("held", self._resend.item, self._resend.line,
                  f"waits to resend {self._resend.line!r} (late-reply window)")
        for job in self._queue:
            if not job.withdrawn:
                entry("queued", job.item, job.line, f"{job.line!r} not sent yet")
        for item in self._waiting:
            entry("awaiting-event", item, None, "waits for an event from the device")
        return out

    def attach(self, session: PerformerSession) -> None:
        """Remember the session, report the notes and start reading the port."""
        self._session = session
        self._sim.attach(session)
        for note in self.notes:
            self._note(note)
        if self._port is not None and self._reader is None:
            self._start_reader(self._port)

    def _peer(self, item: WorkItem) -> DeviceBinding | None:
        """The other binding of this run that serves ``item``'s participant, if any."""
        participant = item.participant or ""
        if participant in self._modes:
            return None
        peer = self.peers.get(participant)
        return peer if isinstance(peer, DeviceBinding) and peer is not self else None

    def offer(self, item: WorkItem) -> None:
        participant = item.participant or ""
        peer = self._peer(item)
        if peer is not None:
            # handed work of a participant bound to another port (the engine routes by
            # participant, SharedApplication; a caller offering directly may not): that
            # port performs it
            peer.offer(item)
            return
        # routed here by Application id (see ``applications``) for a participant this run
        # did not bind to the device: the simulated device performs it
        if self.mode(participant) == "simulated" or (
                participant and participant not in self._modes):
            self._sim.offer(item)
            return
        fallback = self.profile.fallback_for(participant)
        op = self.profile.operation_for(item.application, item.activity)
        if op is None:
            message = (f"{self._who(item)}: profile {self.profile.name!r} has no operation for "
                       f"application {item.application!r} / activity {item.activity!r}")
            self._fault("unknown-operation", message, item=item, action="abort")
            self._session_().fail(item, fallback.exception, message)
            return
        if self.mode(participant) == "aborted":
            message = f"{self._who(item)}: the device on {self.url} is unavailable"
            self._fault("unavailable", message, item=item, action="abort")
            self._session_().fail(item, fallback.exception, message)
            return
        if op.command is None:
            self._waiting.append(item)
            return
        try:
            line = op.command.fill({**op.defaults, **item.data})
        except TemplateError as error:
            message = f"{self._who(item)}: cannot build the command for {op.name!r}: {error}"
            self._fault("missing-data", message, item=item, action="abort")
            self._session_().fail(item, fallback.exception, message)
            return
        self._queue.append(Job(item, op, line))
        self._pump()

    def withdraw(self, item: WorkItem, reason: str) -> None:
        peer = self._peer(item)
        if peer is not None:
            peer.withdraw(item, reason)
            return
        self._sim.withdraw(item, reason)
        self._waiting = [w for w in self._waiting if w.key != item.key]
        for job in (*self._queue, self._inflight):
            if job is not None and job.item.key == item.key:
                job.withdrawn = True  # a command already sent cannot be unsent

    def close(self) -> None:
        """Stop the reader, cancel timers, close the port. Idempotent; any thread."""
        self._closed.set()
        self._connection = "closed"
        for job in (*self._queue, self._inflight):
            if job is not None and job.timer is not None:
                job.timer.cancel()
        if self._hold_timer is not None:
            self._hold_timer.cancel()
        reader, self._reader = self._reader, None
        if reader is not None:
            reader.shutdown()
        elif self._port is not None:
            try:
                self._port.close()
            except (serial.SerialException, OSError):
                pass

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ reporting
    def trace_pending(self, pending: Sequence[Mapping[str, Any]]) -> None:
        """Trace ``pending`` (see :meth:`pending`) as one ``device.pending`` event."""
        if self._session is not None:
            self._session.trace(DEVICE_PENDING, {"device": self.profile.name, "port": self.url,
                                                 "pending": [dict(p) for p in pending]})

    def __repr__(self) -> str:
        return (f"DeviceBinding({self.profile.name!r}, participants={self.participants!r}, "
                f"url={self.url!r}, connection={self._connection!r})")
