"""The bridge from device threads to the engine's thread.

SimPy is not thread-safe, so a reader thread never touches the engine or a
:class:`~opspec.engine.performers.PerformerSession`. It *posts* a callback into an
:class:`Inbox`; the engine (or the TUI loop) calls :meth:`Inbox.drain` on its own thread,
which runs the callbacks there. In wall-clock mode the engine may be asleep until its next
timer: :attr:`Inbox.wake` is called (from the posting thread) after each post so the loop can
wake early and drain at once.

One inbox may be shared by every binding of a run; callbacks run in the order posted.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from typing import Protocol

from opspec.engine.performers import PerformerSession

__all__ = ["Inbox", "InboxLike"]


class InboxLike(Protocol):
    """What the engine loop needs from an inbox."""

    def drain(self, session: PerformerSession | None = None) -> int: ...

    @property
    def pending(self) -> int: ...


class Inbox:
    """A thread-safe queue of callbacks run on the thread that drains it."""

    def __init__(self, wake: Callable[[], None] | None = None) -> None:
        self._queue: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self._posted = threading.Condition()
        self._count = 0
        #: Called on the posting thread after each post; must be thread-safe and quick
        #: (set an event, write to a self-pipe, ``call_soon_threadsafe``).
        self.wake: Callable[[], None] | None = wake

    def post(self, callback: Callable[[], None]) -> None:
        """Queue ``callback`` to run on the draining thread. Safe from any thread."""
        self._queue.put(callback)
        with self._posted:
            self._count += 1
            self._posted.notify_all()
        wake = self.wake
        if wake is not None:
            wake()

    @property
    def pending(self) -> int:
        """Callbacks posted and not yet drained."""
        return self._queue.qsize()

    def drain(self, session: PerformerSession | None = None) -> int:
        """Run every callback posted so far, in order, on the calling thread (the engine's).

        Returns how many ran. ``session`` is accepted so an engine loop can write
        ``inbox.drain(session)``; the callbacks answer through the session their binding
        was attached to, so it is not needed here. Callbacks posted while draining run in
        this call too, so a drain leaves the inbox empty unless other threads keep posting.
        """
        done = 0
        while True:
            try:
                callback = self._queue.get_nowait()
            except queue.Empty:
                return done
            callback()
            done += 1

    def wait(self, timeout: float | None = None, after: int | None = None) -> bool:
        """Block until there is something to drain (with ``after``: until more than ``after``
        callbacks were ever posted), or ``timeout`` seconds pass; returns whether there is.
        For loops without an engine (tests, tools); an engine loop uses :attr:`wake`."""
        with self._posted:
            target = (self._count - self.pending) if after is None else after
            return self._posted.wait_for(lambda: self._count > target, timeout)

    @property
    def posted(self) -> int:
        """How many callbacks were ever posted (for :meth:`wait`'s ``after``)."""
        with self._posted:
            return self._count
