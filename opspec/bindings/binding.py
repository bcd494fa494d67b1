"""DeviceBinding: a Performer whose work is done by a serial device speaking a profile's
line protocol, with the profile's fallback when the device misbehaves.

Threads. pySerial's reader thread and the reply timers never touch the engine: they post
callbacks into the binding's :class:`~opspec.bindings.inbox.Inbox`, which the engine drains
on its own thread. Every method below runs on that engine thread, except where a docstring
says otherwise, so the binding's state needs no locks.

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

import threading
import time
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Any, Final, Literal, Self

import serial

from opspec.bindings.inbox import Inbox
from opspec.bindings.latency import LatencySummary, summarise
from opspec.bindings.profiles import DeviceProfile, Operation
from opspec.bindings.simulated import ProfileSimulator
from opspec.bindings.templates import TemplateError
from opspec.bindings.transport import LineFramer, LineReaderThread, open_port
from opspec.engine.performers import PerformerSession, WorkItem
from opspec.engine.trace import EventKind
from opspec.errors import BindingError

__all__ = ["DEVICE_EVENT", "DEVICE_EXCHANGE", "DEVICE_NOTE", "DEVICE_PENDING", "DeviceBinding"]

DEVICE_EXCHANGE: Final = "device.exchange"   # a command and its reply, with latency
DEVICE_NOTE: Final = "device.note"           # bound / simulated / reconnected / switched
DEVICE_EVENT: Final = "device.event"         # an unsolicited line the profile knows
DEVICE_PENDING: Final = "device.pending"     # work unfinished when the run ended

Mode = Literal["device", "simulated", "aborted"]
Connection = Literal["open", "reconnecting", "gone", "closed", "none"]


@dataclass(eq=False, slots=True)
class _Job:
    """One command for one work item, possibly sent several times."""

    item: WorkItem
    op: Operation
    line: str
    attempts: int = 0
    seq: int = 0
    sent_at: float = 0.0
    timer: threading.Timer | None = None
    withdrawn: bool = False
    last_fault: str = ""
    # what the device sent during this attempt that was not its reply, as (fault, message):
    # the attempt goes on, since a valid reply may still follow (noise lines, a partial
    # frame); reported with the reply, or as the attempt's failure at its timeout
    noise: list[tuple[str, str]] = field(default_factory=list)


class DeviceBinding:
    """Performs the work items of ``participants`` on a device (or on its simulation).

    Build it with :func:`opspec.bindings.bind`; ``port`` is an already open pySerial port
    (``None``: simulated from the start, with ``notes`` saying why). Call :meth:`close` when
    the run ends. ``inbox`` must be drained by the engine's loop (shared by all bindings of a
    run is fine).
    """

    def __init__(self, profile: DeviceProfile, participants: Sequence[str], url: str | None,
                 port: serial.Serial | None, *, inbox: Inbox | None = None,
                 notes: Sequence[str] = ()) -> None:
        self.profile = profile
        self.participants: tuple[str, ...] = tuple(participants)
        self.url = url
        self.inbox = inbox if inbox is not None else Inbox()
        self.notes: list[str] = list(notes)
        #: Round-trip time of every answered command, in seconds (wall clock).
        self.latencies: list[float] = []
        #: The data of every fault reported, in order (also in the trace), plus ``at``: the
        #: simulated time it was reported (None before :meth:`attach`).
        self.faults: list[dict[str, Any]] = []
        self._session: PerformerSession | None = None
        self._sim = ProfileSimulator(profile)
        start: Mode = "device" if port is not None else "simulated"
        self._modes: dict[str, Mode] = {p: start for p in self.participants}
        self._port = port
        self._reader: LineReaderThread | None = None
        self._connection: Connection = "open" if port is not None else "none"
        self._generation = 0
        self._queue: deque[_Job] = deque()
        self._inflight: _Job | None = None
        self._waiting: list[WorkItem] = []          # passive operations awaiting an event
        self._timed_out: deque[_Job] = deque()       # replies we gave up waiting for
        # after a timeout the line is held (nothing is sent) until the late reply comes or
        # the late-reply window passes; ``_resend`` is the job to send again then, if any
        self._held: _Job | None = None
        self._resend: _Job | None = None
        self._hold_timer: threading.Timer | None = None
        self._holds = 0
        self._seq = 0
        self._closed = threading.Event()
        self._newline = profile.serial.newline.encode()

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

    def mode(self, participant: str | None) -> Mode:
        """``device``, ``simulated`` or ``aborted`` for ``participant``."""
        return self._modes.get(participant or "", "device" if self._port else "simulated")

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

    def offer(self, item: WorkItem) -> None:
        participant = item.participant or ""
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
        self._queue.append(_Job(item, op, line))
        self._pump()

    def withdraw(self, item: WorkItem, reason: str) -> None:
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

    # ------------------------------------------------------------------ reader side
    def _start_reader(self, port: serial.Serial) -> None:
        self._generation += 1
        gen = self._generation
        post = self.inbox.post

        def factory() -> LineFramer:
            # these three run on the reader thread: post only, never touch state
            return LineFramer(
                self.profile.serial,
                on_line=lambda text, at: post(partial(self._on_line, gen, text, at)),
                on_garbage=lambda raw, at, why: post(partial(self._on_garbage, gen, raw, why)),
                on_lost=lambda exc: post(partial(self._on_lost, gen, exc)),
            )

        self._port = port
        self._reader = LineReaderThread(port, factory)
        self._reader.name = f"serial-{self.profile.name}"
        self._reader.start()
        self._connection = "open"

    # ------------------------------------------------------------------ sending
    def _pump(self) -> None:
        """Send the next queued command if the line is free (one command at a time)."""
        while (self._inflight is None and self._held is None and self._queue
               and self._connection == "open"):
            job = self._queue.popleft()
            if job.withdrawn:
                continue
            participant = job.item.participant
            if self.mode(participant) != "device":
                self._reroute(job)
                continue
            fallback = self.profile.fallback_for(participant)
            if job.attempts > fallback.retries:
                self._give_up(job, f"{job.last_fault or 'failed'} after {job.attempts} "
                              "attempt(s)")
                continue
            self._send(job)

    def _send(self, job: _Job) -> None:
        assert self._reader is not None
        self._seq += 1
        job.seq, job.attempts = self._seq, job.attempts + 1
        self._inflight = job
        data = job.line.encode(self.profile.serial.encoding, "replace") + self._newline
        job.sent_at = time.perf_counter()
        try:
            self._reader.write(data)
        except (serial.SerialException, OSError) as error:
            self._disconnected(error, "writing")
            return
        timer = threading.Timer(job.op.timeout_s, self.inbox.post,
                                (partial(self._on_timeout, job.seq),))
        timer.daemon = True
        job.timer = timer
        timer.start()

    def _finish(self, job: _Job) -> None:
        if job.timer is not None:
            job.timer.cancel()
        if self._inflight is job:
            self._inflight = None

    # ------------------------------------------------------------------ receiving
    def _on_line(self, gen: int, text: str, at: float) -> None:
        if gen != self._generation or self._connection == "closed":
            return
        job = self._inflight
        if job is not None:
            for template in job.op.ok:
                values = template.match(text)
                if values is not None:
                    self._answered(job, text, at, values, None)
                    return
            for template, exception in job.op.errors:
                if template.match(text) is not None:
                    self._answered(job, text, at, None, exception)
                    return
        held = self._held
        if job is None and held is not None and self._answers(held.op, text):
            self._late_reply(held, text, at)
            self._release(self._holds)          # the line is clean again: go on at once
            return
        for rule in self.profile.events.values():
            values = rule.line.match(text)
            if values is not None:
                self._on_event(rule.name, rule.trigger, rule.complete, values, text)
                return
        if any(t.match(text) is not None for t in self.profile.ignore):
            return
        if job is not None:
            # not (yet) the reply: a debug line, a partial frame, a device's noise. The
            # command may well have been carried out (a drawer that dispensed), so the
            # attempt waits on for its reply; only its timeout ends it.
            job.noise.append(("unexpected-line", f"unexpected reply {text!r} to {job.line!r}"))
        elif self._timed_out and self._is_reply(text):
            self._late_reply(self._timed_out.popleft(), text, at)
        else:
            self._fault("unexpected-line", f"{self._label()}: unexpected line {text!r} from "
                        f"{self.url}", reply=text)

    def _on_garbage(self, gen: int, raw: bytes, why: str) -> None:
        if gen != self._generation or self._connection == "closed":
            return
        message = f"garbled data from {self.url} ({why}): {raw[:40]!r}"
        if self._inflight is not None:       # the reply may follow (see _on_line)
            self._inflight.noise.append(("garbage", message))
        else:
            self._fault("garbage", f"{self._label()}: {message}")

    def _late_reply(self, late: _Job, text: str, at: float) -> None:
        """A reply to a command that timed out: a fault, never an answer (its latency is in
        the fault, not among the round trips)."""
        if late in self._timed_out:
            self._timed_out.remove(late)
        self._fault("late-reply", f"{self._who(late.item)}: reply {text!r} to {late.line!r} "
                    f"came after its {late.op.timeout_s * 1000:g} ms timeout", item=late.item,
                    line=late.line, reply=text, latency=at - late.sent_at, attempt=late.attempts)

    @staticmethod
    def _answers(op: Operation, text: str) -> bool:
        return any(t.match(text) is not None for t in (*op.ok, *(e[0] for e in op.errors)))

    def _is_reply(self, text: str) -> bool:
        return any(self._answers(op, text) for op in self.profile.operations.values())

    def _answered(self, job: _Job, text: str, at: float, values: Mapping[str, Any] | None,
                  exception: str | None) -> None:
        self._finish(job)
        if job.noise:       # the reply came after noise: read, and the noise reported
            kind, first = job.noise[0]
            more = f" (and {len(job.noise) - 1} more line(s))" if len(job.noise) > 1 else ""
            self._fault("garbage" if any(k == "garbage" for k, _ in job.noise) else kind,
                        f"{self._who(job.item)}: {first}{more} before the reply {text!r}, "
                        "which was read", item=job.item, line=job.line, reply=text,
                        attempt=job.attempts)
            job.noise.clear()
        latency = at - job.sent_at
        self.latencies.append(latency)
        details: dict[str, Any] = {"device": self.profile.name, "participant": job.item.participant,
                                   "activity": job.item.activity, "command": job.line,
                                   "reply": text, "latency": latency, "attempt": job.attempts}
        if exception is not None:
            details["exception"] = exception
        self._session_().trace(DEVICE_EXCHANGE, details)
        if exception is not None:
            # an answer, but the device could not do the work: counted with the faults
            self._fault("device-error", f"{self._who(job.item)}: the device answered {text!r} "
                        f"to {job.line!r} ({exception})", item=job.item, action="exception",
                        line=job.line, reply=text, exception=exception)
        if not job.withdrawn:
            if exception is None:
                self._session_().complete(job.item, dict(values) if values else None)
            else:
                self._session_().fail(job.item, exception,
                                      f"{self._who(job.item)}: the device answered {text!r} "
                                      f"to {job.line!r}")
        self._pump()

    def _on_event(self, name: str, trigger: str | None, complete: str | None,
                  values: Mapping[str, Any], text: str) -> None:
        session = self._session_()
        session.trace(DEVICE_EVENT, {"device": self.profile.name, "event": name, "line": text,
                                     "data": dict(values)})
        done = False
        if complete is not None:
            for item in self._waiting:
                if complete in (item.application, item.activity):
                    self._waiting.remove(item)
                    session.complete(item, dict(values) or None)
                    done = True
                    break
        if trigger is not None:
            session.raise_trigger(trigger, dict(values) or None)
        elif not done:
            self._note(f"{self._label()}: event {name!r} ignored: no activity {complete!r} "
                       "was waiting for it")

    # ------------------------------------------------------------------ faults
    def _on_timeout(self, seq: int) -> None:
        job = self._inflight
        if job is None or job.seq != seq or self._connection == "closed":
            return  # answered (or superseded) meanwhile
        self._timed_out.append(job)
        if job.noise:       # it answered only with noise: garbage, as a garbled reply is
            kind, first = job.noise[0]
            more = f" (and {len(job.noise) - 1} more line(s))" if len(job.noise) > 1 else ""
            job.noise.clear()
            retry = self._report_attempt(
                job, "garbage", f"{self._who(job.item)}: {first}{more}, and no valid reply "
                f"within {job.op.timeout_s * 1000:g} ms")
        else:
            retry = self._report_attempt(job, "timeout", f"{self._who(job.item)}: no reply "
                                         f"to {job.line!r} within "
                                         f"{job.op.timeout_s * 1000:g} ms")
        fallback = self.profile.fallback_for(job.item.participant)
        if not retry:   # the fallback applies now; the line is still held for the late reply
            self._give_up(job, f"timeout after {job.attempts} attempt(s)")
        self._hold(job, job if retry else None, fallback.late_reply_s)

    def _hold(self, job: _Job, resend: _Job | None, window_s: float | None) -> None:
        """Send nothing until ``job``'s late reply comes or ``window_s`` (default: its
        timeout) passes; then resend ``resend`` (if any) and the queue."""
        self._holds += 1
        self._held, self._resend = job, resend
        timer = threading.Timer(job.op.timeout_s if window_s is None else window_s,
                                self.inbox.post, (partial(self._release, self._holds),))
        timer.daemon = True
        self._hold_timer = timer
        timer.start()

    def _release(self, hold: int) -> None:
        """End the hold ``hold`` (if it is still the current one) and go on sending."""
        if hold != self._holds or self._held is None:
            return
        self._end_hold()
        if self._connection == "open":
            self._pump()

    def _end_hold(self) -> None:
        """Stop holding the line: the hold timer stops and the command to resend (if any)
        goes back to the front of the queue."""
        if self._hold_timer is not None:
            self._hold_timer.cancel()
        if self._resend is not None:
            self._queue.appendleft(self._resend)
        self._held = self._resend = self._hold_timer = None

    def _report_attempt(self, job: _Job, fault: str, message: str) -> bool:
        """End ``job``'s failed attempt and report the fault with what follows; whether
        it is retried (else the participant's fallback applies)."""
        self._finish(job)
        fallback = self.profile.fallback_for(job.item.participant)
        retry = job.attempts <= fallback.retries
        job.last_fault = fault
        self._fault(fault, message, item=job.item, action="retry" if retry else fallback.then,
                    line=job.line, attempt=job.attempts)
        return retry

    def _give_up(self, job: _Job, reason: str) -> None:
        participant = job.item.participant or ""
        fallback = self.profile.fallback_for(participant)
        if fallback.then == "simulate":
            if fallback.scope == "run":
                self._switch_to_simulated(participant, reason)
            else:
                self._note(f"{participant or self.profile.name}: {job.line!r}: {reason}; "
                           "simulated this once, the next command goes to the device")
            if not job.withdrawn:
                self._sim.offer(job.item)
        elif not job.withdrawn:
            self._session_().fail(job.item, fallback.exception,
                                  f"{self._who(job.item)}: {job.line!r} failed: {reason}")

    def _switch_to_simulated(self, participant: str, reason: str) -> None:
        if self._modes.get(participant) == "simulated":
            return
        self._modes[participant] = "simulated"
        self._note(f"{participant or self.profile.name}: {reason}; using the simulated "
                   f"{participant or self.profile.name} from now on")
        for item in [w for w in self._waiting if (w.participant or "") == participant]:
            self._waiting.remove(item)
            self._sim.offer(item)
        # commands queued for it (the line may stay held for a while) go simulated now too
        for job in [j for j in self._queue if (j.item.participant or "") == participant]:
            self._queue.remove(job)
            self._reroute(job)

    def _reroute(self, job: _Job) -> None:
        """A queued job whose participant left the device: simulate it or fail it."""
        if job.withdrawn:
            return
        if self.mode(job.item.participant) == "simulated":
            self._sim.offer(job.item)
        else:
            fallback = self.profile.fallback_for(job.item.participant)
            message = f"{self._who(job.item)}: the device on {self.url} is unavailable"
            self._session_().fail(job.item, fallback.exception, message)

    def _on_lost(self, gen: int, exc: BaseException | None) -> None:
        if gen != self._generation or self._connection != "open" or self._closed.is_set():
            return
        self._disconnected(exc, "reading")

    def _disconnected(self, exc: BaseException | None, doing: str) -> None:
        """The port failed: close it, report, and reconnect (on a helper thread) or fall back."""
        reason = str(exc) if exc is not None else "the port was closed"
        self._generation += 1  # lines still queued from the dead reader are ignored
        # the dead reader is shut down on a helper thread, never here: closing a port can
        # block (pySerial's socket:// sleeps 0.3 s in close()), which would stall a
        # wall-clock run by thousands of simulated seconds at high speed factors
        dead, self._reader = self._reader, None
        if self._held is not None:        # a reopened line starts clean: no hold needed
            self._holds += 1
            self._end_hold()
        job, self._inflight = self._inflight, None
        if job is not None:
            if job.timer is not None:
                job.timer.cancel()
            job.last_fault = "disconnected"
            self._queue.appendleft(job)
        attempts = self.profile.fallback.reconnect_attempts
        self._connection = "reconnecting"
        self._fault("disconnected", f"{self._label()}: {self.url} failed while {doing}: {reason}",
                    item=job.item if job else None, line=job.line if job else None,
                    action="reconnect" if attempts else "fallback")
        if attempts == 0:
            if dead is not None:
                threading.Thread(target=dead.shutdown, name=f"close-{self.profile.name}",
                                 daemon=True).start()
            self._reconnect_failed(self._generation, "no reconnection attempts declared")
            return
        gen = self._generation
        threading.Thread(target=self._reconnect_worker, args=(gen, attempts, dead),
                         name=f"reconnect-{self.profile.name}", daemon=True).start()

    def _reconnect_worker(self, gen: int, attempts: int,
                          dead: LineReaderThread | None = None) -> None:
        """Helper thread: close the dead port, try to reopen it; post the outcome to the
        engine."""
        assert self.url is not None
        if dead is not None:
            if "://" in self.url:
                # a URL transport needs no exclusive access: reconnect while it closes
                threading.Thread(target=dead.shutdown, name=f"close-{self.profile.name}",
                                 daemon=True).start()
            else:
                dead.shutdown()   # a device path must be released before it is reopened
        last = ""
        try:
            for _ in range(attempts):
                if self._closed.wait(self.profile.fallback.reconnect_delay_s):
                    return
                try:
                    port = open_port(self.url, self.profile.serial)
                except BindingError as error:
                    last = error.message
                    continue
                if self.profile.serial.settle_s and "://" not in self.url:
                    self._closed.wait(self.profile.serial.settle_s)
                self.inbox.post(partial(self._reconnected, gen, port))
                return
        except Exception as error:  # noqa: BLE001 - the engine must hear back, whatever happens
            last = f"{type(error).__name__}: {error}"
        self.inbox.post(partial(self._reconnect_failed, gen,
                                f"{attempts} reconnection attempt(s) failed: {last}"))

    def _reconnected(self, gen: int, port: serial.Serial) -> None:
        if gen != self._generation or self._closed.is_set():
            # not on the engine's thread: a socket:// close sleeps (see _disconnected)
            threading.Thread(target=port.close, name=f"close-{self.profile.name}",
                             daemon=True).start()
            return
        self._start_reader(port)
        self._note(f"{self._label()}: reconnected to {self.url}")
        self._pump()

    def _reconnect_failed(self, gen: int, reason: str) -> None:
        if gen != self._generation or self._closed.is_set():
            return
        self._connection = "gone"
        actions = sorted({self.profile.fallback_for(p).then for p in self.participants})
        self._fault("reconnect-failed", f"{self._label()}: cannot reopen {self.url}: {reason}",
                    action="/".join(actions))
        for participant in self.participants:
            if self.profile.fallback_for(participant).then == "simulate":
                self._switch_to_simulated(participant, f"{self.url} is gone")
            else:
                self._modes[participant] = "aborted"
                for item in [w for w in self._waiting if (w.participant or "") == participant]:
                    self._waiting.remove(item)
                    self._session_().fail(item, self.profile.fallback_for(participant).exception,
                                          f"{participant}: the device on {self.url} is gone")
        jobs, self._queue = list(self._queue), deque()
        for job in jobs:
            if self.mode(job.item.participant) == "device":
                self._modes[job.item.participant or ""] = "aborted"  # an unlisted participant
            self._reroute(job)

    # ------------------------------------------------------------------ reporting
    def _fault(self, fault: str, message: str, *, item: WorkItem | None = None,
               action: str = "none", line: str | None = None, **extra: Any) -> None:
        data: dict[str, Any] = {"fault": fault, "device": self.profile.name, "port": self.url,
                                "message": message, "action": action}
        if item is not None:
            data.update(participant=item.participant, activity=item.activity,
                        instance=item.instance, item=item.key)
        if line is not None:
            data["command"] = line
        data.update(extra)
        # the report gives each fault's simulated time (the trace event carries it already)
        self.faults.append({**data, "at": self._session.now if self._session else None})
        if self._session is not None:
            self._session.trace(EventKind.FAULT, data)

    def trace_pending(self, pending: Sequence[Mapping[str, Any]]) -> None:
        """Trace ``pending`` (see :meth:`pending`) as one ``device.pending`` event."""
        if self._session is not None:
            self._session.trace(DEVICE_PENDING, {"device": self.profile.name, "port": self.url,
                                                 "pending": [dict(p) for p in pending]})

    def _note(self, message: str) -> None:
        if message not in self.notes:
            self.notes.append(message)
        if self._session is not None:
            self._session.trace(DEVICE_NOTE, {"device": self.profile.name, "port": self.url,
                                              "message": message})

    def _session_(self) -> PerformerSession:
        if self._session is None:
            raise RuntimeError(f"DeviceBinding for {self._label()} used before attach()")
        return self._session

    def _who(self, item: WorkItem) -> str:
        return item.participant or self._label()

    def _label(self) -> str:
        return ", ".join(self.participants) or self.profile.name

    def __repr__(self) -> str:
        return (f"DeviceBinding({self.profile.name!r}, participants={self.participants!r}, "
                f"url={self.url!r}, connection={self._connection!r})")
