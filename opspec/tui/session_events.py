"""What a walkthrough session follows in the run's trace, event by event: the instances
running and their deadlines, the work a device has not answered yet, each participant's last
action, fault or note, the user-lane calls, and where a call from the device begins."""

from __future__ import annotations

from opspec.engine.trace import TraceEvent
from opspec.tui.session_clock import time_of_day_shown
from opspec.tui.session_state import SessionState

__all__ = ["TraceFollower"]

_ANSWERED = frozenset({"activity.completed", "activity.omitted", "activity.failed",
                       "activity.withdrawn", "activity.aborted", "deadline.expired"})


class TraceFollower(SessionState):
    """The trace listener of a :class:`~opspec.tui.session.WalkSession`."""

    def _on_event(self, event: TraceEvent) -> None:
        self.events.append(event)
        kind = event.kind
        if kind == "activity.withdrawn" and event.activity:
            gone = [o.item.key for o in self.offers if o.item.instance == event.instance
                    and o.item.activity == event.activity]
            self._drop_offers(*gone)
            self.lane_user.items = {k: i for k, i in self.lane_user.items.items() if not (
                i.instance == event.instance and i.activity == event.activity)}
        if event.instance is not None and event.activity and event.lane != "user":
            if kind == "activity.offered":
                self.device_work.add((event.instance, event.activity))
            elif kind in _ANSWERED:
                self.device_work.discard((event.instance, event.activity))
        if event.instance is not None and event.activity and (
                event.instance not in self.lapsed_instances):
            if kind in ("activity.started", "activity.offered"):
                self.current[event.instance] = (event.process or "", event.activity)
                for seconds, _sync, _exc in self._deadline_of.get(
                        (event.process or "", event.activity), ()):
                    try:
                        due = float(seconds({}, event.time))
                    except Exception:  # noqa: BLE001, S112 - a data-dependent deadline: not shown
                        continue
                    self.deadlines[(event.instance, event.activity)] = event.time + due
            elif kind in ("activity.completed", "deadline.expired", "activity.withdrawn",
                          "activity.aborted", "activity.omitted"):
                self.deadlines.pop((event.instance, event.activity), None)
        if kind.startswith("process.") and kind != "process.started" and (
                event.instance is not None):
            self._drop_instance(event.instance)
            self.device_work = {w for w in self.device_work if w[0] != event.instance}
            self.current.pop(event.instance, None)
            self.deadlines = {k: v for k, v in self.deadlines.items()
                              if k[0] != event.instance}
        if kind == "activity.completed" and event.participant and event.lane != "user":
            self.participants[event.participant] = (
                f"{event.activity} at {time_of_day_shown(event.time)}")
        if kind in ("fault", "device.note"):
            data = event.data or {}
            who = str(data.get("participant") or data.get("device") or "device")
            prefix = "FAULT: " if kind == "fault" else "note: "
            self.participants[who] = prefix + str(data.get("message", ""))
        if kind == "process.started" and event.lane == "user":
            self.calls += 1
        self.aftermath(event)
        if not self._in_call and self.calling and self.person_performs:
            self._call_began = True          # the stepping loop stops and applies on_call
        elif self._in_call and not self.calling:
            self._follow_call()
        for listener in self.listeners:
            listener(event)
