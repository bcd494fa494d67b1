"""``opspec run``'s printed timeline: every event (``--timeline all``) or the brief one.

The brief timeline shows what a reader follows (:data:`BRIEF_KINDS`, without the completions
of routes, start and end events and other activities that do no work) and *folds* the
repetitions of periodic workflows: a robot spec runs a workflow five times a second, so an
hour is some 76,000 instances and, shown one line per event, a quarter of a million lines
nobody can follow. Per periodic workflow (started by its ``opspec:Rate``/``opspec:Period``
timer more often than once a :data:`WINDOW`; a daily reminder is not folded) the first :data:`FULL` instances are shown in full; after that an instance's start,
completion and routine steps are counted instead, and each step (activity, choice, raised
trigger) is still shown the first :data:`FULL` times it happens in that workflow, so a new
path appears when it is first taken. Once per :data:`WINDOW` simulated seconds a line per
workflow says how many instances were folded and how often each step ran. Deadline misses,
exceptions, terminations, failures, mode changes, faults and deadlocks are always shown.
``--timeline all`` shows every event, and the trace file (``--trace``) is never shortened.

The brief printer is a *raw* listener (it gets an event's fields, not a
:class:`~opspec.engine.trace.TraceEvent`) selecting only the brief kinds, so the engine builds
no event object for what it folds or leaves out; an event object is made only for a line.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from opspec.clock import clock_time

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledPackage
    from opspec.engine.lane_labels import LaneLabels
    from opspec.engine.trace import TraceEvent

__all__ = ["BRIEF_KINDS", "FULL", "WINDOW", "AllTimeline", "BriefTimeline", "quiet_activities"]

# Kinds shown in the default (brief) timeline: what a reader follows; the full trace has all.
BRIEF_KINDS = frozenset({
    "process.started", "process.completed", "process.terminated", "process.aborted",
    "activity.completed", "activity.omitted", "activity.failed", "activity.aborted",
    "activity.withdrawn", "trigger.raised", "deadline.expired", "exception.raised",
    "mode.changed", "fault", "deadlock", "device.note", "user.decision",
})

#: instances of a periodic workflow shown in full, and times each of its steps is shown
FULL = 3
#: simulated seconds per folded line of a periodic workflow
WINDOW = 60.0

_PERIOD = "period"          # the trigger label of an instance started by its period timer
_ENDS = frozenset({"process.terminated", "process.aborted"})


def quiet_activities(compiled: CompiledPackage) -> frozenset[tuple[str, str]]:
    """(process, activity) pairs whose completion says nothing to a reader: routes, start and
    end events, and other activities that do no work."""
    from opspec.engine.compiled import K_GATEWAY, K_NOOP
    from opspec.engine.lanes import all_activities

    return frozenset((a.process, a.id) for a in all_activities(compiled)
                     if a.kind in (K_NOOP, K_GATEWAY) and a.sampler is None and not a.raises)


class _Printer:
    """What both timelines share: the output, the lanes' labels and the lines counted."""

    def __init__(self, out: Any, lanes: LaneLabels | None) -> None:
        from opspec.engine.lane_labels import PLAIN

        self.out = out
        self.lanes = lanes if lanes is not None else PLAIN
        self.shown = 0

    def line(self, event: TraceEvent) -> None:
        from opspec.engine.trace_text import timeline_line

        self.shown += 1
        print(timeline_line(event, self.lanes), file=self.out)

    def finish(self, end: float) -> None:
        """The run ended at simulated time ``end``: print what is still held (nothing here)."""


class AllTimeline(_Printer):
    """``--timeline all``: every event, as it happens."""

    selects = None

    def __call__(self, event: TraceEvent) -> None:
        self.line(event)


class _Fold:
    """The folded instances of one periodic workflow in the current window."""

    __slots__ = ("instances", "lane", "started", "steps")

    def __init__(self, lane: str | None) -> None:
        self.lane = lane
        self.started = 0                 # instances started by the period timer, ever
        self.instances = 0               # of them folded in this window
        self.steps: dict[str, int] = {}  # step -> times folded in this window


class BriefTimeline(_Printer):
    """The default timeline: the brief kinds, periodic workflows folded (module docstring)."""

    selects = frozenset((kind, None, None) for kind in BRIEF_KINDS)

    def __init__(self, out: Any, compiled: CompiledPackage, lanes: LaneLabels | None = None,
                 *, full: int = FULL, window: float = WINDOW) -> None:
        from opspec.engine.lanes import all_activities

        super().__init__(out, lanes)
        self.quiet = quiet_activities(compiled)
        self.full = full
        self.window = window
        # the lane each event is traced with (an activity's, else its process's): the line
        # is made here from the raw fields, as the engine would have made the event
        self.proc_lane = {p.id: p.lane for p in compiled.processes.values()}
        self.act_lane = {(a.process, a.id): a.lane for a in all_activities(compiled)}
        self.package = compiled.id
        #: the workflows folded: started by a period timer more often than once a window
        self.periodic = tuple(
            p.id for p in compiled.processes.values()
            if p.start_trigger is not None and p.start_trigger.kind == _PERIOD
            and 0.0 < (p.start_trigger.every or 0.0) < window)
        self._periodic = frozenset(self.periodic)
        self.folds: dict[str, _Fold] = {}
        self.folded: set[int] = set()          # live instances being folded
        self.seen: dict[tuple[str, str], int] = {}   # (process, step) -> times shown
        self.window_end = window
        self.window_start = 0.0

    def raw(self, time: float, kind: str, process: str | None, instance: int | None,
            activity: str | None, data: Mapping[str, Any] | None = None) -> None:
        if kind not in BRIEF_KINDS:          # another listener's kind (raw hears them all)
            return
        if time >= self.window_end:
            self._close_windows(time)
        if kind == "process.started":
            if process in self._periodic and data and data.get("trigger") == _PERIOD:
                fold = self.folds.get(process)
                if fold is None:
                    fold = self.folds[process] = _Fold(self.proc_lane.get(process))
                fold.started += 1
                if fold.started > self.full and instance is not None:
                    self.folded.add(instance)
                    fold.instances += 1
                    return
        elif kind == "activity.completed":
            choice = (data or {}).get("choice")
            if (process or "", activity or "") in self.quiet or (
                    activity is None and "choice" not in (data or {})):
                return
            if process is not None and process in self.folds:
                step = f"{activity} (chose {choice})" if choice else str(activity)
                if self._fold_step(process, instance, step):
                    return
        elif kind == "trigger.raised":
            if process is not None and process in self.folds:
                step = f"trigger {(data or {}).get('name', '?')}"
                if self._fold_step(process, instance, step):
                    return
        elif kind == "process.completed":
            if instance in self.folded:
                self.folded.discard(instance)
                return
        elif kind in _ENDS:
            self.folded.discard(instance)
        elif kind == "exception.raised":    # the deadline line already said it
            if "deadline" in str((data or {}).get("message", "")):
                return
        self._show(time, kind, process, instance, activity, data)

    def _fold_step(self, process: str, instance: int | None, step: str) -> bool:
        """Count ``step`` of a periodic workflow's instance: False (show it) for the first
        :attr:`full` times it happens in that workflow, True (folded) afterwards when the
        instance is folded."""
        key = (process, step)
        times = self.seen.get(key, 0)
        if times < self.full:
            self.seen[key] = times + 1
            return False
        if instance not in self.folded:
            return False
        steps = self.folds[process].steps
        steps[step] = steps.get(step, 0) + 1
        return True

    def _show(self, time: float, kind: str, process: str | None, instance: int | None,
              activity: str | None, data: Mapping[str, Any] | None) -> None:
        from opspec.engine.trace import TraceEvent

        if activity is not None:            # traced with its activity's lane
            lane = self.act_lane.get((process or "", activity))
        elif kind.startswith(("trigger.", "mode.")):
            lane = None                      # raised by no activity: traced without a lane
        else:
            lane = self.proc_lane.get(process) if process is not None else None
        self.line(TraceEvent(time, kind, process, instance, activity, lane, None,
                             self.package, data or {}))

    def _close_windows(self, time: float) -> None:
        """Print the folded lines of the window that ended, then move on to the window
        holding ``time`` (windows in which nothing was folded print nothing)."""
        self._flush(self.window_end)
        passed = int((time - self.window_start) // self.window)
        self.window_start += passed * self.window
        self.window_end = self.window_start + self.window

    def _flush(self, at: float) -> None:
        from opspec.engine.trace import TraceEvent

        for process, fold in self.folds.items():
            if not fold.instances and not fold.steps:
                continue
            text = (f"... {fold.instances:,} more instance{'s' if fold.instances != 1 else ''}"
                    f" since {clock_time(self.window_start)}")
            if fold.steps:
                text += ": " + ", ".join(f"{step} {n:,}" for step, n in fold.steps.items())
            event = TraceEvent(at, "folded", process, None, None, fold.lane, None,
                               self.package, {})
            self.shown += 1
            print(f"{clock_time(at):>16}  {self.lanes.label(event):<{self.lanes.width}} "
                  f"{self.lanes.where(event)} {text}", file=self.out)
            fold.instances = 0
            fold.steps = {}

    def finish(self, end: float) -> None:
        """The run ended at ``end``: the last, partial window's folded lines."""
        self._flush(max(end, self.window_start))
