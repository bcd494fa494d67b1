"""The one seam through which manual and external activities are performed.

A :class:`Performer` is offered :class:`WorkItem` values and answers through the
:class:`PerformerSession` the engine gives it: complete, omit, fail, raise a trigger, or ask to
be called back later in *simulated* time. Performers never see the clock: user models, scripted
users, the TUI, serial devices and Python callables all plug in here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, Protocol, runtime_checkable

from opspec.engine.workitem import WorkItem

__all__ = ["Performer", "PerformerSession", "WorkItem"]


class PerformerSession(Protocol):
    """What the engine offers a performer. All times are simulated seconds."""

    @property
    def now(self) -> float: ...

    def complete(self, item: WorkItem, data: Mapping[str, Any] | None = None,
                 choice: str | None = None) -> None:
        """The activity is done; ``data`` updates data fields; ``choice`` picks an alternative."""

    def omit(self, item: WorkItem, reason: str = "") -> None:
        """The performer does not perform it (an omission): the instance's path ends here."""

    def fail(self, item: WorkItem, exception: str, message: str = "") -> None:
        """The activity failed with a named exception (follows an EXCEPTION transition)."""

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        """Send a message/signal trigger (e.g. the user's report sets ``trg_1``)."""

    def call_later(self, delay: float, callback: Callable[[], None]) -> None:
        """Run ``callback`` after ``delay`` simulated seconds (on the engine's thread)."""

    def trace(self, kind: str, data: Mapping[str, Any] | None = None) -> None:
        """Record a performer-side event (a fault, a note) in the trace."""


@runtime_checkable
class Performer(Protocol):
    """Performs work items for the participants or lanes it is bound to."""

    def attach(self, session: PerformerSession) -> None:
        """Called once before the run starts."""

    def offer(self, item: WorkItem) -> None:
        """An activity instance now waits for this performer."""

    def withdraw(self, item: WorkItem, reason: str) -> None:
        """An offered item is no longer wanted (deadline passed, another branch won)."""
