"""The port of a bound device: its reader thread, whose lines, garbage and loss are posted
to the engine's inbox; a lost port reopened on a helper thread (the profile's reconnection
attempts), or given up, its participants then simulated or aborted."""

from __future__ import annotations

import threading
from collections import deque
from functools import partial
from pathlib import Path

import serial

from opspec.bindings.binding_state import BindingState
from opspec.bindings.transport import LineFramer, LineReaderThread, open_port, settles
from opspec.errors import BindingError

__all__ = ["Reconnection"]


class Reconnection(BindingState):
    """The port's reader and its reconnection (a part of
    :class:`~opspec.bindings.binding.DeviceBinding`)."""

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

    # ------------------------------------------------------------------ reconnecting
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
                    port = open_port(self.url, self.profile.serial,
                                     profiles_dir=Path(self.profile.path).parent)
                except BindingError as error:
                    last = error.message
                    continue
                if self.profile.serial.settle_s and settles(self.url):
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
