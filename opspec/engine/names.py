"""The names a spec defines: what tests, scripts, monitors and predicates may refer to."""

from __future__ import annotations

from dataclasses import dataclass

from opspec.engine.compiled import CompiledPackage
from opspec.engine.lanes import all_activities

__all__ = ["SpecNames", "spec_names"]


@dataclass(frozen=True, slots=True)
class SpecNames:
    """The names a spec defines, for checking what tests and scripts refer to."""

    processes: tuple[str, ...]
    activities: tuple[str, ...]
    triggers: tuple[str, ...]
    metrics: tuple[str, ...]
    user_performers: tuple[str, ...]


def spec_names(compiled: CompiledPackage) -> SpecNames:
    """Processes, activities, trigger (message/signal) names, metrics, and the names the user
    lane's performers bind to (participants of user-lane activities, else their lane)."""
    activities: dict[str, None] = {}
    triggers: dict[str, None] = {}
    user: dict[str, None] = {}
    for act in all_activities(compiled):
        activities[act.id] = None
        for trig in (act.raises, act.trigger, act.start_trigger, act.end_trigger):
            if trig is not None and trig.name and trig.kind in ("message", "signal"):
                triggers[trig.name] = None
        if act.user_lane:
            name = act.participant or (act.lanes[0] if act.lanes else None)
            if name:
                user[name] = None
    for proc in compiled.processes.values():
        for trig in (proc.start_trigger, proc.end_trigger):
            if trig is not None and trig.name and trig.kind in ("message", "signal"):
                triggers[trig.name] = None
    return SpecNames(tuple(compiled.processes), tuple(activities), tuple(triggers),
                     tuple(m.name for m in compiled.package.metrics), tuple(user) or ("user",))
