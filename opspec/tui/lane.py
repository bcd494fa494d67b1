"""The user lane in a walkthrough: what the person is offered, and who performs it.

:class:`LaneUser` is the lane's performer. It keeps every work item the engine offered the
lane and has not taken back (:attr:`LaneUser.items`), whoever holds it: the person (then the
item is shown as :class:`Offer` values by the session) or a user model the person handed the
lane to. A model acts through a :class:`RecordingSession`, so its actions are recorded like
the person's; taking the lane back *revokes* that session (a model's delayed action that
fires later does nothing) and hands the items it held back to the person.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from opspec.engine.performers import PerformerSession, WorkItem
from opspec.tui.replay import tagged_action

if TYPE_CHECKING:
    from opspec.tui.session import WalkSession

__all__ = ["LaneUser", "Offer", "RecordingSession"]


@dataclass(frozen=True, slots=True)
class Offer:
    """Something the person can do now: an activity, or one alternative of a choice.

    ``choice_label`` is the alternative's name in the spec (``Press "report"``)."""

    item: WorkItem
    choice: str | None          # the alternative, for a deferred choice
    choice_label: str | None = None

    @property
    def label(self) -> str:
        return self.choice_label or self.choice or self.item.label or self.item.activity

    @property
    def action(self) -> str:
        """The recorded action, naming the instance (``complete hear_alarm #6``): a replay
        acts on the same one of several identical offers."""
        if self.choice:
            return tagged_action("choose", self.choice, self.item.instance)
        return tagged_action("complete", self.item.activity, self.item.instance)


class LaneUser:
    """The user lane's performer: holds offers for the person, or passes them to a model."""

    def __init__(self, session: WalkSession) -> None:
        self.walk = session
        #: every item offered to the lane and not yet done or withdrawn (key -> item)
        self.items: dict[int, WorkItem] = {}
        self.engine: PerformerSession | None = None
        self.model: Any = None
        self.model_session: RecordingSession | None = None

    def attach(self, session: PerformerSession) -> None:
        self.engine = session

    def offer(self, item: WorkItem) -> None:
        self.items[item.key] = item
        if self.model is not None:
            self.model.offer(item)
            return
        self.walk._offered(item)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        self.items.pop(item.key, None)
        self.walk._drop_offers(item.key)
        if self.model is not None:
            self.model.withdraw(item, reason)

    def hand_over(self, model: Any, items: list[WorkItem]) -> None:
        """``model`` performs the lane from now on, starting with ``items``."""
        if self.engine is not None:
            self.model_session = RecordingSession(self.walk, self.engine)
            model.attach(self.model_session)
        self.model = model
        for item in items:
            model.offer(item)

    def take_back(self) -> list[WorkItem]:
        """The model stops: its session is revoked, what it held is withdrawn from it and
        returned (oldest offer first) for the person."""
        model, self.model = self.model, None
        if self.model_session is not None:
            self.model_session.active = False
            self.model_session = None
        held = sorted(self.items.values(), key=lambda i: i.key)
        for item in held:
            model.withdraw(item, "the person took the lane back")
        return held


class RecordingSession:
    """The engine session a handed-over model sees: its actions are recorded like the
    person's, so a replay without the model gives the same trace. Once revoked
    (``active = False``, the person took the lane back) every call does nothing."""

    def __init__(self, walk: WalkSession, engine: PerformerSession) -> None:
        self.walk = walk
        self.engine = engine
        self.active = True

    @property
    def now(self) -> float:
        return self.engine.now

    def _take(self, item: WorkItem) -> bool:
        """Whether the model may act on ``item`` now (and it is no longer pending)."""
        if not self.active or item.key not in self.walk.lane_user.items:
            return False
        del self.walk.lane_user.items[item.key]
        return True

    def complete(self, item: WorkItem, data: Mapping[str, Any] | None = None,
                 choice: str | None = None) -> None:
        if not self._take(item):
            return
        self.walk._record(tagged_action("choose", choice, item.instance) if choice
                          else tagged_action("complete", item.activity, item.instance),
                          by="model", item=item)
        self.engine.complete(item, data, choice)

    def omit(self, item: WorkItem, reason: str = "") -> None:
        if not self._take(item):
            return
        self.walk._record(tagged_action("omit", item.activity, item.instance), by="model",
                          item=item)
        self.engine.omit(item, reason)

    def fail(self, item: WorkItem, exception: str, message: str = "") -> None:
        if not self._take(item):
            return
        self.walk._record(tagged_action("fail", item.activity, item.instance, exception),
                          by="model", item=item)
        self.engine.fail(item, exception, message)

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        if self.active:
            self.walk._record(f"raise {name}", by="model")
            self.engine.raise_trigger(name, data)

    def call_later(self, delay: float, callback: Callable[[], None]) -> None:
        def later() -> None:
            if self.active:             # a revoked model's timers do nothing
                callback()

        self.engine.call_later(delay, later)

    def trace(self, kind: str, data: Mapping[str, Any] | None = None) -> None:
        if self.active:
            self.engine.trace(kind, data)
