"""What the person's last action led to, told from the trace (the "what happened" line).

A wrong button in a real device often does nothing visible; in a walkthrough the person must
still learn what their action did. :class:`Aftermath` listens to the trace after each of the
person's actions and keeps its immediate consequences — the events at the same simulated
instant: triggers the action sent, whether the device was waiting for them (``trigger.kept``:
nobody was; ``trigger.lost``), what the device did in answer, and what the person is asked
next. :meth:`Aftermath.text` says it in one line::

    you: Hear the alarm at 12:09 -> your own action, nothing sent to the device -> asked next:
         Walk to the dispenser
    you: Press "report" at 12:09 -> sent trg_1 -> the device: Wait for the user's report
         (trg_1), Dispense the dose -> asked next: Take the pill
    you did not: Hear the alarm at 08:00 -> nothing sent to the device
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from typing import Any

from opspec.engine.trace import TraceEvent

__all__ = ["Aftermath"]

_SHOWN = 3                         # device activities named (then "and N more")


class Aftermath:
    """See the module docstring. ``label_of(process, activity)`` gives the spec's name of an
    activity; ``quiet`` lists (process, activity) pairs that do no work (routes, start and end
    events), which are not worth telling."""

    def __init__(self, label_of: Callable[[str, str], str],
                 quiet: Collection[tuple[str, str]] = ()) -> None:
        self._label_of = label_of
        self._quiet = frozenset(quiet)
        self.label = ""
        self.at = 0.0
        self._open = False
        self.sent: list[str] = []
        self.kept: list[str] = []
        self.lost: list[str] = []
        self.device: list[str] = []
        self.asked: list[str] = []

    def acted(self, label: str, item: Any, now: float) -> None:
        """The person did ``label`` at simulated time ``now``: collect what follows."""
        self.label, self.at, self._open = label, now, True
        self.sent, self.kept, self.lost, self.device, self.asked = [], [], [], [], []

    def __call__(self, event: TraceEvent) -> None:
        if not self._open:
            return
        if event.time > self.at:
            self._open = False           # only the immediate consequences
            return
        kind, data = event.kind, event.data or {}
        name = str(data.get("name", "?"))
        if kind == "trigger.raised" and event.lane == "user":
            self.sent.append(name)
        elif kind == "trigger.kept":
            self.kept.append(name)
        elif kind == "trigger.lost":
            self.lost.append(name)
        elif event.activity and event.process is not None:
            where = (event.process, event.activity)
            if kind == "activity.completed" and event.lane != "user" and (
                    where not in self._quiet):
                self.device.append(self._label_of(*where))
            elif kind == "activity.offered" and event.lane == "user":
                self.asked.append(self._label_of(*where))

    @property
    def shown(self) -> bool:
        return bool(self.label)

    def text(self) -> str:
        """One line: what the person did, and what it led to."""
        if not self.label:
            return ""
        rest = self.at % 86_400.0
        # an omission (x) is labelled "not: …" (opspec.tui.session_lane): not done, so not
        # "your own action"
        omitted = self.label.startswith("not: ")
        did = f"you did not: {self.label[5:]}" if omitted else f"you: {self.label}"
        parts = [f"{did} at {int(rest // 3600):02d}:{int(rest % 3600 // 60):02d}"]
        if self.sent:
            parts.append("sent " + ", ".join(self.sent))
        if self.kept or self.lost:
            parts.append(f"but the device was not waiting for {', '.join(self.kept + self.lost)}"
                         + (" (kept a while, then lost)" if self.kept else " (lost)"))
        if self.device:
            named = ", ".join(dict.fromkeys(self.device[:_SHOWN]))
            more = len(self.device) - _SHOWN
            parts.append(f"the device: {named}" + (f" and {more} more" if more > 0 else ""))
        elif not self.kept and not self.lost:
            # nothing sent: hearing an alarm, walking, a button wired to nothing are the
            # person's own doing, which by design involves no device (not a fault); sent:
            # caught (neither kept nor lost), but no device activity finished at this instant
            parts.append("no device activity at once" if self.sent
                         else "nothing sent to the device" if omitted
                         else "your own action, nothing sent to the device")
        if self.asked:
            parts.append("asked next: " + ", ".join(dict.fromkeys(self.asked)))
        return " -> ".join(parts)
