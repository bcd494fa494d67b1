"""The lane column of a text timeline: each event's lane in the spec's own words, one width.

A trace event carries the lane its activity sits in as the spec names it: ``device`` or
``user`` (an ``opspec:Lane`` directive), or a pool lane's id (``guard_lane`` for a BPMN
``<lane id="guard_lane" name="Stove guard">``), and no lane for a process-wide event. A reader
wants the lane's name, and the columns after it in one place on every line, whether the spec
has lanes or not. :func:`lane_labels` reads both from the compiled package once: the label of
every lane an event can carry, the label of each process's own events (its activities' lane
when they all share one; ``device`` for a process in no lane), which activities belong to the
user lane (a lane named ``Resident`` is the user lane when its work is manual), and the widths
that keep the columns aligned.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from opspec.engine.lanes import all_activities

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledPackage

__all__ = ["LaneLabels", "lane_labels"]

#: the longest lane label shown in full; a longer lane name is cut with an ellipsis so that
#: one long BPMN lane name does not push every other line's columns to the right
MAX_LANE = 16
#: the widest process#instance column kept aligned (longer ones overflow on their own line)
MAX_WHERE = 32
#: the narrowest columns (a spec without lanes: ``device``/``user`` and the dispenser's ids)
WIDTH = 7
WHERE = 24
DEVICE = "device"
USER = "user"


def _cut(label: str, width: int) -> str:
    return label if len(label) <= width else label[:width - 1] + "…"


@dataclass(frozen=True, slots=True)
class LaneLabels:
    """See the module docstring. ``names``: lane as traced → label; ``process_lane``: process
    id → the label of its process-wide events; ``user_activities``: (process, activity) of the
    user lane; ``width`` / ``where_width``: the lane and process#instance columns."""

    names: dict[str, str]
    process_lane: dict[str, str]
    user_activities: frozenset[tuple[str, str]]
    width: int = WIDTH
    #: workflows that are the user lane's as a whole (their own start, end, deadlock)
    user_processes: frozenset[str] = frozenset()
    where_width: int = WHERE

    def label(self, event: Any) -> str:
        """The lane of ``event`` in words (``""`` for an event of no process, such as the
        run's start, and for a process-wide event of a process spanning several lanes)."""
        lane = event.lane
        if lane:
            return _cut(self.names.get(lane, lane), self.width)
        if event.process is None:
            return ""
        if event.activity is not None and self.is_user(event):
            # an activity in no lane of a user workflow (its end event, drawn with no
            # performer) is shown in the workflow's lane, as its other activities are
            own = (self.process_lane.get(event.process, "")
                   if event.process in self.user_processes else "")
            return _cut(own or USER, self.width)
        return _cut(self.process_lane.get(event.process, DEVICE), self.width)

    def is_user(self, event: Any) -> bool:
        """Whether ``event`` is the user lane's (its activity is, or its lane is ``user``)."""
        if event.lane == USER:
            return True
        if event.activity is None:
            return (event.process or "") in self.user_processes
        return (event.process or "", event.activity) in self.user_activities

    def where(self, event: Any) -> str:
        """``process#instance`` (or the process alone), padded to the column's width."""
        where = (f"{event.process or ''}#{event.instance}" if event.instance is not None
                 else event.process or "")
        return f"{where:<{self.where_width}}"


#: what a timeline without a compiled package shows (the lane as traced, the old widths)
PLAIN = LaneLabels(names={}, process_lane={}, user_activities=frozenset())


def lane_labels(compiled: CompiledPackage) -> LaneLabels:
    """The labels and column widths of every event of a run of ``compiled``."""
    names: dict[str, str] = {}
    for pool in compiled.package.pools:
        for lane in pool.all_lanes():
            # a directive's word (device, user) is shown as it is; a pool lane by its name
            if lane.id and lane.id not in (DEVICE, USER):
                names[lane.id] = lane.name or lane.id
    # a BPMN process drawn without a pool keeps its lanes as participants of the same id
    named = {p.id: p.name for p in compiled.package.participants if p.name}
    per_process: dict[str, set[str]] = {pid: set() for pid in compiled.processes}
    user: set[tuple[str, str]] = set()
    activities = list(all_activities(compiled))
    for act in activities:
        if act.lane and act.lane not in names and act.lane not in (DEVICE, USER) \
                and act.lane in named:
            names[act.lane] = named[act.lane]
    for act in activities:
        if act.user_lane:
            user.add((act.process, act.id))
        if act.lane:
            per_process.setdefault(act.process, set()).add(names.get(act.lane, act.lane))
    process_lane: dict[str, str] = {}
    # a workflow is the user's when every activity placed in a lane is the user lane's; its
    # activities in no lane (an end event drawn outside the lane) are then the user's too
    every: dict[str, list[bool]] = {}
    for act in activities:
        if act.lanes:
            every.setdefault(act.process, []).append(act.user_lane)
    user_processes = frozenset(
        pid for pid, proc in compiled.processes.items()
        if proc.lane == USER or (every.get(pid) and all(every[pid])))
    user.update((act.process, act.id) for act in activities
                if not act.lanes and act.process in user_processes)
    for pid, proc in compiled.processes.items():
        if proc.lane:
            process_lane[pid] = names.get(proc.lane, proc.lane)
        elif len(per_process.get(pid, ())) == 1:
            process_lane[pid] = next(iter(per_process[pid]))
        elif per_process.get(pid):
            process_lane[pid] = ""               # its events belong to no single lane
        else:
            process_lane[pid] = USER if pid in user_processes or any(
                p == pid for p, _a in user) else DEVICE
    shown = {DEVICE, *process_lane.values(), *names.values(),
             *(lane for labels in per_process.values() for lane in labels)}
    if user:
        shown.add(USER)
    width = max(WIDTH, min(MAX_LANE, max(len(label) for label in shown)))
    # process#instance: room for four-digit instance numbers after the longest process id
    where = min(MAX_WHERE, max((len(pid) for pid in compiled.processes), default=0) + 5)
    return LaneLabels(names=names, process_lane=process_lane,
                      user_activities=frozenset(user), width=width,
                      where_width=max(where, WHERE), user_processes=user_processes)
