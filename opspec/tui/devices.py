"""What each device participant is doing, derived from the trace alone (no engine internals).

:class:`DeviceBoard` is a trace listener. For every participant that performs device-lane
activities (in spec order) it keeps:

- **signalling**: the trigger the participant raised towards the user and is still sounding
  (the alarm rings from ``sound_alarm``'s ``trg_2`` until its instance moves on: the report
  arrives or the deadline expires);
- **busy**: the activities it is in right now (``wait_report``);
- **last**: the last activity it completed, with its simulated time (``Dispense the dose``);
- **display**: the data fields its activities set (``alarms=2``, ``outcome=taken``);
- **fault** / **note**: the last device fault (trace kind ``fault``) or ``device.note`` of a
  bound device, put on the participant it concerns (the one its message names first, else
  every participant the device serves: ``device_participants``). A fault without a participant
  (a port that disappeared) goes to every participant the device serves.

A BPMN pool or lane is a participant too: the events and gateways drawn in it, which nobody
performs, are put on it. Where its workflow has performers of its own (the dispenser pool's
alarm and pill drawer), the pool is not a device beside them: it gets no row (unless it
signals the user or faults), so the panel lists the devices the diagram's reader knows, once,
as the XPDL version of the spec lists them. A pool or lane that has a row is shown by the
name the diagram gives it (``Stove guard appliance``, not ``guard_lane``, an id no modeller
shows).

The Textual view renders :meth:`DeviceBoard.rows`; tests assert on them directly.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from opspec.engine.compiled import CompiledPackage
from opspec.engine.lanes import all_activities
from opspec.engine.trace import TraceEvent
from opspec.model.activities import Event, Route

__all__ = ["DeviceBoard", "ParticipantRow", "ParticipantState"]

# Participants whose signal is a sound: their signal reads RINGING / silent.
_SOUNDING = re.compile(r"alarm|buzz|bell|ring|chime|beep|siren", re.IGNORECASE)
_FINISHED = frozenset({"activity.completed", "activity.aborted", "activity.failed",
                       "activity.withdrawn", "activity.omitted"})


@dataclass
class ParticipantState:
    """The mutable state of one participant (owned by :class:`DeviceBoard`)."""

    id: str
    name: str
    sounding: bool = False
    signalling: dict[int, tuple[str, str, float]] = field(default_factory=dict)
    busy: dict[tuple[int, str], str] = field(default_factory=dict)
    last: tuple[str, float] | None = None
    display: dict[str, str] = field(default_factory=dict)
    fault: tuple[str, str, float] | None = None     # (kind, message, time)
    note: str | None = None


@dataclass(frozen=True, slots=True)
class ParticipantRow:
    """One participant as the view shows it: ``status`` is words (never colour alone);
    ``alert`` says the row deserves emphasis (a fault, a ringing alarm)."""

    id: str
    name: str
    status: str
    detail: str
    alert: bool
    #: what the panel calls it: the participant's id, a BPMN pool's or lane's name
    shown: str = ""


class DeviceBoard:
    """See the module docstring. Call it with every trace event, in order."""

    def __init__(self, compiled: CompiledPackage,
                 device_participants: Mapping[str, Sequence[str]] | None = None) -> None:
        names = {p.id: (p.name or p.id) for p in compiled.package.participants}
        self._owner: dict[tuple[str, str], tuple[str, str]] = {}
        self.states: dict[str, ParticipantState] = {}
        for act in all_activities(compiled):
            if act.user_lane or not act.participant:
                continue
            self._owner[(act.process, act.id)] = (act.participant, act.label or act.id)
            if act.participant not in self.states:
                pid = act.participant
                self.states[pid] = ParticipantState(
                    pid, names.get(pid, pid),
                    sounding=bool(_SOUNDING.search(pid) or _SOUNDING.search(names.get(pid, ""))))
        #: pools and lanes standing in for the performers of their workflow: no row of their own
        self.pools, self.hidden = _pools_and_lanes(compiled)
        #: device name (profile) → the participants it serves, for faults without a participant
        self.device_participants = {k: tuple(v) for k, v in (device_participants or {}).items()}
        #: every device note seen in the trace (the view lists other notes apart), in order
        self.notes: list[str] = []
        self.notes_seen: set[str] = set()

    # ------------------------------------------------------------------ events
    def __call__(self, event: TraceEvent) -> None:
        kind = event.kind
        if kind in ("fault", "device.note"):
            self._device_event(event)
            return
        instance = event.instance
        if instance is None or event.lane == "user":
            return
        owner = self._owner.get((event.process or "", event.activity or ""))
        # the instance moved on: signals raised earlier in it stop
        ended = kind.startswith("process.") and kind != "process.started"
        if kind in ("activity.completed", "deadline.expired") or ended:
            for state in self.states.values():
                raised = state.signalling.get(instance)
                if raised is not None and (raised[1] != event.activity or kind != (
                        "activity.completed")):
                    del state.signalling[instance]
        if ended:
            for state in self.states.values():
                state.busy = {k: v for k, v in state.busy.items() if k[0] != instance}
        if owner is None or event.activity is None:
            return
        state = self.states[owner[0]]
        if kind == "activity.started":
            state.busy[(instance, event.activity)] = owner[1]
        elif kind in _FINISHED:
            state.busy.pop((instance, event.activity), None)
            if kind == "activity.completed":
                state.last = (owner[1], event.time)
        elif kind == "trigger.raised":
            name = str((event.data or {}).get("name", "?"))
            state.signalling[instance] = (name, event.activity, event.time)
        elif kind == "data.changed":
            for key, value in (event.data or {}).items():
                state.display[str(key)] = _short(value)

    def _device_event(self, event: TraceEvent) -> None:
        data = event.data or {}
        message = str(data.get("message", "") or data.get("fault", ""))
        if event.kind == "device.note" and message not in self.notes_seen:
            self.notes_seen.add(message)
            self.notes.append(message)
        who: tuple[str, ...]
        if data.get("participant"):
            who = (str(data["participant"]),)
        else:
            # a message that names one participant first ("dispenser: …", of a device that
            # serves the alarm too) is that participant's; else it concerns the whole device
            device = str(data.get("device") or "device")
            who = _mentioned(message, self.states) or self.device_participants.get(device) or (
                device,)
        for pid in who:
            state = self.states.get(pid)
            if state is None:
                state = self.states[pid] = ParticipantState(pid, pid)
            if event.kind == "fault":
                state.fault = (str(data.get("fault") or "fault"), message, event.time)
            else:
                state.note = message

    # ------------------------------------------------------------------ view
    def rows(self) -> list[ParticipantRow]:
        """One row per participant, in spec order (devices seen only in faults last)."""
        out = []
        for state in self.states.values():
            if state.id in self.hidden and state.fault is None and not state.signalling:
                continue
            last = f"last: {state.last[0]} {_hhmm(state.last[1])}" if state.last else ""
            alert = True
            if state.fault is not None:
                status = f"FAULT at {_hhmm(state.fault[2])}: {state.fault[0]}"
            elif state.signalling:
                name, _activity, since = next(iter(state.signalling.values()))
                status = (f"((( RINGING ))) since {_hhmm(since)}" if state.sounding
                          else f"(!) SIGNALLING {name} since {_hhmm(since)}")
            else:
                alert = False
                if state.busy:
                    status = f"> {next(iter(state.busy.values()))}"
                elif state.sounding:
                    status = "silent"
                elif last:
                    status, last = last, ""
                else:
                    status = "idle"
            parts = [state.fault[1]] if state.fault is not None else []
            parts.extend([last] if last else [])
            parts.extend(f"{k}={v}" for k, v in state.display.items())
            if state.note and state.fault is None:
                parts.append(f"note: {state.note}")
            out.append(ParticipantRow(
                state.id, state.name, status, "  ".join(parts), alert,
                state.name if state.id in self.pools else state.id))
        return out

    @property
    def ringing(self) -> bool:
        """Whether any participant is signalling the user now."""
        return any(s.signalling for s in self.states.values())


def _pools_and_lanes(compiled: CompiledPackage) -> tuple[frozenset[str], frozenset[str]]:
    """The pools and lanes (of a BPMN diagram) that are participants, and of those the ones
    that perform only the events and gateways drawn in them, in a workflow where someone else
    performs the work (a task, a call)."""
    package = compiled.package
    containers = {pool.participant or pool.id for pool in package.pools}
    containers.update(lane.id for pool in package.pools for lane in pool.all_lanes())
    structural: set[tuple[str, str]] = set()     # the events and gateways, by workflow
    for process in package.processes:
        for activity in process.all_activities():
            containers.update([activity.lane] if activity.lane else [])
            if isinstance(activity.body, Event | Route):
                structural.add((process.id, activity.id))
    owns: dict[str, set[str]] = {}        # pool or lane -> the workflows it has activities in
    doers: dict[str, set[str]] = {}       # workflow -> who performs its work
    working: set[str] = set()             # pools and lanes that perform work themselves
    for act in all_activities(compiled):
        who = act.participant or ""
        if who in containers:
            owns.setdefault(who, set()).add(act.process)
        if (act.process, act.id) not in structural:
            doers.setdefault(act.process, set()).add(who)
            working.add(who)
    return frozenset(owns), frozenset(
        who for who, processes in owns.items() if who not in working
        and any(doers.get(p, set()) - {who} for p in processes))


def _mentioned(message: str, states: Mapping[str, ParticipantState]) -> tuple[str, ...]:
    """Participants a device message names first (``alarm: reconnected …``)."""
    head = message.split(":", 1)[0].strip()
    return (head,) if head in states else ()


def _short(value: object) -> str:
    text = str(value)
    return text if len(text) <= 16 else text[:15] + "…"


def _hhmm(seconds: float) -> str:
    rest = seconds % 86_400.0
    return f"{int(rest // 3600):02d}:{int(rest % 3600 // 60):02d}"
