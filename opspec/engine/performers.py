"""The one seam through which manual and external activities are performed.

A :class:`Performer` is offered :class:`WorkItem` values and answers through the
:class:`PerformerSession` the engine gives it: complete, omit, fail, raise a trigger, or ask to
be called back later in *simulated* time. Performers never see SimPy: user models, scripted
users, the TUI, serial devices and Python callables all plug in here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any, NamedTuple, Protocol, runtime_checkable

__all__ = ["Performer", "PerformerSession", "WorkItem"]


class WorkItem(NamedTuple):
    """An activity instance offered to a performer (immutable).

    ``key`` is unique per run and identifies the offer in every call back to the session.
    ``choices`` lists alternative activity ids when the person may pick one of several
    (a deferred choice / event-based gateway); it is empty otherwise. ``duration`` is a draw
    from the activity's declared duration distribution (``None`` when it declares none), for
    performers that simulate the work (``SimulatedDevice``).

    A named tuple rather than a frozen dataclass for speed: the engine builds one per offer
    (several per dose cycle of the dispenser), and a 13-field frozen dataclass costs about
    2.5 us to construct (``object.__setattr__`` per field) against 0.3 us for a named tuple.
    Read it by field name; do not rely on its tuple order.
    """

    key: int
    process: str
    instance: int
    activity: str
    label: str
    participant: str | None
    lane: str | None
    offered_at: float
    application: str | None = None
    data: Mapping[str, Any] = MappingProxyType({})
    choices: tuple[str, ...] = ()
    root_instance: int | None = None
    duration: float | None = None      # drawn from the activity's declared duration, if any


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
