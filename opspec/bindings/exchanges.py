"""The profile's line protocol on a bound device: one command at a time sent for a work
item, its reply read (or an error reply, noise, garbage, an event, a late reply) and its
timeout; after a timeout the line is held until the late reply comes or its window passes,
then the command is sent again or the fallback applies (see the :mod:`~opspec.bindings.binding`
docstring for the faults and the noise rules)."""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping
from functools import partial
from typing import Any

import serial

from opspec.bindings.binding_state import DEVICE_EVENT, DEVICE_EXCHANGE, BindingState, Job
from opspec.bindings.profiles import Operation

__all__ = ["Exchanges"]


class Exchanges(BindingState):
    """Sending commands and reading their replies (a part of
    :class:`~opspec.bindings.binding.DeviceBinding`)."""

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

    def _send(self, job: Job) -> None:
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

    def _finish(self, job: Job) -> None:
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
        if self.url is not None and "://" not in self.url:
            # on a serial line, garbage is mostly a baud rate the device does not use
            why += (f"; is {self.profile.serial.baudrate} baud, the profile's [serial] "
                    "baudrate, the device's?")
        message = f"garbled data from {self.url} ({why}): {raw[:40]!r}"
        if self._inflight is not None:       # the reply may follow (see _on_line)
            self._inflight.noise.append(("garbage", message))
        else:
            self._fault("garbage", f"{self._label()}: {message}")

    def _late_reply(self, late: Job, text: str, at: float) -> None:
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

    def _answered(self, job: Job, text: str, at: float, values: Mapping[str, Any] | None,
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

    # ------------------------------------------------------------------ timeouts and the hold
    def _on_timeout(self, seq: int) -> None:
        job = self._inflight
        if job is None or job.seq != seq or self._connection == "closed":
            return  # answered (or superseded) meanwhile
        self._timed_out.append(job)
        if job.noise:       # it answered only with noise: garbage, as a garbled reply is
            _kind, first = job.noise[0]
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

    def _hold(self, job: Job, resend: Job | None, window_s: float | None) -> None:
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

    def _report_attempt(self, job: Job, fault: str, message: str) -> bool:
        """End ``job``'s failed attempt and report the fault with what follows; whether
        it is retried (else the participant's fallback applies)."""
        self._finish(job)
        fallback = self.profile.fallback_for(job.item.participant)
        retry = job.attempts <= fallback.retries
        job.last_fault = fault
        self._fault(fault, message, item=job.item, action="retry" if retry else fallback.then,
                    line=job.line, attempt=job.attempts)
        return retry
