"""OCEL 2.0 export: the simulated traces as an object-centric event log (JSON format).

XES forces one case notion on every event; an object-centric log relates each event to every
object it concerns, so one log answers questions about users, doses and devices at once. The
format is the JSON serialisation of OCEL 2.0 (https://www.ocel-standard.org): a document
with ``objectTypes``, ``eventTypes``, ``objects`` and ``events``, each event with its
``relationships`` (object id and qualifier). ``pm4py.read_ocel2`` reads it.

Objects of one simulated user (design ``A``, user 3 → ids ending in ``A/3``):

- ``user A/3``: the simulated user (type ``user``);
- ``device A/3``: the user's device, everything the device lane does (type ``device``);
- ``A/3/timer_workflow#1``: one chain of workflow instances (:mod:`.cases`: for the
  dispenser, one dose; for a stove guard, one cooking session), typed after the spec's own
  workflow that starts the chain (``timer_workflow``, ``guard_workflow``): the same id as
  the chain's case in the XES and JSONL exports;
- one object per other person the spec declares (a ``HUMAN`` participant that does not
  perform the user lane, e.g. ``caregiver A/3``; its type is the participant id).

Event relationships (qualifiers): the user — ``performed by`` for user-lane events, ``for``
otherwise; the device — ``performed by`` for the other lanes' events; the chain — ``part of``;
another person — ``performed by`` when they perform the activity, ``concerns`` when the
activity names them (its id, name or application mentions the participant's id or name:
``notify_caregiver``). Object-to-object: the device, each chain and each other person relate
to the user (``belongs to``, ``for``, ``cares for``).

The events are those of the XES export (:data:`.exporters.DEFAULT_XES_KINDS`), typed
``qualified/activity transition`` (``user_workflow/take_pill complete``), with the same
attributes as XES events (``opspec:kind``, ``opspec:instance``, ``opspec:time``, the event's
data). Written streaming: the events go straight to ``<path>.partial``; objects to a side file
joined at the end, so memory does not grow with the number of users.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from datetime import datetime, timedelta
from pathlib import Path
from typing import IO, Any

from opspec.engine.trace import EventKind, TraceEvent
from opspec.evaluation.cases import ChainTracker
from opspec.evaluation.exporters import (
    DEFAULT_EPOCH,
    DEFAULT_XES_KINDS,
    LIFECYCLE_TRANSITIONS,
    _StreamingWriter,
    qualified_name,
)

__all__ = ["OcelWriter", "People", "people_of"]


@dataclass(frozen=True, slots=True)
class People:
    """Who is who in the spec, for the objects of the log: the participants that perform
    the user lane, the other people (participant id → object type) and, per activity
    ``(process, activity)``, the other people it concerns."""

    user: frozenset[str] = frozenset({"user"})
    others: Mapping[str, str] = field(default_factory=dict)
    mentions: Mapping[tuple[str, str], tuple[str, ...]] = field(default_factory=dict)
    #: the user lane's work as the compiled spec has it: activities ``(process, activity)``
    #: and whole workflows (a user workflow's own start and end), whatever its lane is called
    user_activities: frozenset[tuple[str, str]] = frozenset()
    user_processes: frozenset[str] = frozenset()

    def performs(self, event: TraceEvent) -> bool:
        """Whether ``event`` is the user lane's (the simulated user performs it)."""
        if event.lane == "user":
            return True
        if event.activity is None:
            return (event.process or "") in self.user_processes
        return (event.process or "", event.activity) in self.user_activities


def people_of(package: Any, user_participants: Iterable[str],
              compiled: Any = None) -> People:
    """The :class:`People` of a loaded package (:class:`opspec.model.Package`); with its
    ``compiled`` package, which events are the user lane's work (a BPMN lane "Resident", a
    user workflow with no lane directive)."""
    user = frozenset(user_participants)
    humans = [p for p in getattr(package, "participants", ())
              if getattr(p, "is_human", False) and p.id not in user]
    others = {p.id: p.id for p in humans}
    words = {p.id: {w for w in {p.id.lower(), (p.name or "").lower()} if len(w) >= 3}
             for p in humans}
    mentions: dict[tuple[str, str], tuple[str, ...]] = {}
    for process in getattr(package, "processes", ()):
        for activity in process.all_activities():
            body = activity.body
            text = " ".join(str(x) for x in (activity.id, activity.name,
                                              getattr(body, "application", None)) if x)
            tokens = set(re.split(r"[^a-z0-9]+", text.lower()))
            concerned = tuple(pid for pid, names in words.items()
                              if any(w in tokens or (" " in w and w in text.lower())
                                     for w in names))
            if concerned:
                mentions[(process.id, activity.id)] = concerned
    if compiled is None:
        return People(user, others, mentions)
    from opspec.engine.lane_labels import lane_labels

    lanes = lane_labels(compiled)
    return People(user, others, mentions, lanes.user_activities, lanes.user_processes)


_INT_RANGE = (-(2**63), 2**63 - 1)


def _attributes(values: Mapping[str, Any], declared: dict[str, str],
                **extra: Any) -> list[dict[str, Any]]:
    """The OCEL attribute entries of the ``values`` that are set (with ``extra`` keys, such as
    an object attribute's time), each one's type added to ``declared`` (the first seen
    stays)."""
    entries = []
    for name, value in values.items():
        if value is None:
            continue
        kind_of, json_value = _typed(value)
        declared.setdefault(name, kind_of)
        entries.append({"name": name, **extra, "value": json_value})
    return entries


def _typed(value: Any) -> tuple[str, Any]:
    """(OCEL attribute type, JSON value) of a Python value."""
    if isinstance(value, bool):
        return "boolean", value
    if isinstance(value, int) and _INT_RANGE[0] <= value <= _INT_RANGE[1]:
        return "integer", value
    if isinstance(value, float):
        return ("float", value) if math.isfinite(value) else ("float", str(value))
    if isinstance(value, datetime):
        return "time", value.isoformat(timespec="milliseconds")
    if isinstance(value, str):
        return "string", value
    return "string", json.dumps(value, default=str, sort_keys=True)


class OcelWriter(_StreamingWriter):
    """Writes an OCEL 2.0 JSON log, one simulated user (all their days) per :meth:`add_case`.

    ``epoch`` is the wall-clock instant of simulated time 0 (as for XES); ``kinds`` the event
    kinds exported (default: those of the XES export); ``people`` who performs the user lane
    and who else the spec declares (:func:`people_of`); ``lane_names`` lane id → the lane's
    name for ``org:group`` (a lane without one stays its id).
    """

    def __init__(self, path: Path, *, log_attributes: Mapping[str, Any] | None = None,
                 epoch: datetime = DEFAULT_EPOCH, kinds: Collection[str] = DEFAULT_XES_KINDS,
                 people: People | None = None,
                 lane_names: Mapping[str, str] | None = None) -> None:
        self.epoch = epoch
        self.kinds = frozenset(kinds) & frozenset(LIFECYCLE_TRANSITIONS)
        self.people = people or People()
        self._lanes = dict(lane_names or {})
        # OCEL 2.0 has no log-level attributes: ``log_attributes`` is accepted for the
        # writers' one interface and not written
        self.objects = 0
        self._ids = 0
        self._event_types: dict[str, dict[str, str]] = {}
        # the chains' types (their root workflows) are declared as they first occur
        self._object_types: dict[str, dict[str, str]] = {"user": {}, "device": {}}
        for kind in self.people.others.values():
            self._object_types.setdefault(kind, {})
        self._first_event = True
        super().__init__(path)
        self._objects_path = self.path.with_name(self.path.name + ".objects.partial")
        try:
            self._objects_file: IO[str] | None = open(  # noqa: SIM115 (closed in _finish)
                self._objects_path, "w", encoding="utf-8")
        except OSError as error:
            self._abandon()
            raise self._error(error) from None
        self._write('{"events": [\n')

    # ------------------------------------------------------------------ objects

    def _object(self, oid: str, kind: str, attributes: Mapping[str, Any],
                relationships: Iterable[tuple[str, str]] = ()) -> None:
        stamp = self.epoch.isoformat(timespec="milliseconds")
        declared = self._object_types.setdefault(kind, {})
        attrs = _attributes(attributes, declared, time=stamp)
        doc = {"id": oid, "type": kind, "attributes": attrs,
               "relationships": [{"objectId": o, "qualifier": q} for o, q in relationships]}
        assert self._objects_file is not None
        try:
            if self.objects:
                self._objects_file.write(",\n")
            self._objects_file.write(json.dumps(doc, ensure_ascii=False))
        except OSError as error:
            raise self._error(error) from None
        self.objects += 1

    # ------------------------------------------------------------------ events

    def add_case(self, case_id: str, events: Iterable[TraceEvent],
                 attributes: Mapping[str, Any] | None = None) -> None:
        """Write one simulated user's events (``case_id`` such as ``A/3``) and objects."""
        self._check_open()
        user = f"user {case_id}"
        device = f"device {case_id}"
        self._object(user, "user", {"case": case_id, **dict(attributes or {})})
        self._object(device, "device", {}, [(user, "belongs to")])
        others: dict[str, str] = {}
        chains = ChainTracker()
        chained: set[int] = set()
        written = 0
        try:
            for event in events:
                chains.see(event)
                if event.kind not in self.kinds:
                    continue
                by_user = self.people.performs(event)
                relations = [(user, "performed by" if by_user else "for")]
                if not by_user:
                    relations.append((device, "performed by"))
                root = chains.root(event.instance)
                if root is not None:
                    chain = f"{case_id}/{chains.name(root)}"
                    if root not in chained:
                        chained.add(root)
                        process = chains.name(root).split("#")[0]
                        self._object(chain, self._chain_type(process),
                                     {"process": process, "instance": root},
                                     [(user, "for"), (device, "on")])
                    relations.append((chain, "part of"))
                for person, qualifier in self._people(event):
                    oid = others.get(person)
                    if oid is None:
                        oid = others[person] = f"{person} {case_id}"
                        self._object(oid, self.people.others[person], {},
                                     [(user, "cares for")])
                    relations.append((oid, qualifier))
                self._event(event, relations)
                written += 1
        except BaseException:
            self._abandon()
            raise
        self.cases += 1
        self.events += written

    def _chain_type(self, process: str) -> str:
        """A chain's object type: its root workflow's id, unless a workflow is named like
        one of the other types (``user``, ``device``, a person's participant id)."""
        taken = {"user", "device", *self.people.others.values()}
        return process if process not in taken else f"{process} workflow"

    def _people(self, event: TraceEvent) -> list[tuple[str, str]]:
        found: list[tuple[str, str]] = []
        performer = event.participant
        if performer is not None and performer in self.people.others:
            found.append((performer, "performed by"))
        for person in self.people.mentions.get((event.process or "", event.activity or ""),
                                               ()):
            if person != event.participant:
                found.append((person, "concerns"))
        return found

    def _event(self, event: TraceEvent, relations: list[tuple[str, str]]) -> None:
        name = self._name(event)
        kind = f"{name} {LIFECYCLE_TRANSITIONS[event.kind]}"
        declared = self._event_types.setdefault(kind, {})
        values: dict[str, Any] = {"opspec:kind": event.kind, "opspec:time": float(event.time)}
        if event.instance is not None:
            values["opspec:instance"] = int(event.instance)
        if event.participant is not None:
            values["org:resource"] = event.participant
        if event.lane is not None:
            values["org:group"] = self._lanes.get(event.lane, event.lane)
        for key, value in (event.data or {}).items():
            values[f"opspec:{key}"] = value
        attrs = _attributes(values, declared)
        self._ids += 1
        doc = {"id": f"e{self._ids}", "type": kind,
               "time": (self.epoch + timedelta(seconds=float(event.time))).isoformat(
                   timespec="milliseconds"),
               "attributes": attrs,
               "relationships": [{"objectId": o, "qualifier": q} for o, q in relations]}
        text = json.dumps(doc, ensure_ascii=False)
        self._write(text if self._first_event else ",\n" + text)
        self._first_event = False

    def _name(self, event: TraceEvent) -> str:
        process, activity = event.process or "", event.activity
        if event.kind == EventKind.PROCESS_ABORTED:
            return f"process:{process}"
        if event.kind == EventKind.DEADLINE_EXPIRED:
            return f"deadline:{qualified_name(process, activity or process)}"
        if event.kind == EventKind.FAULT:
            return f"fault:{qualified_name(process, activity) if activity else process}"
        return qualified_name(process, activity) if activity else event.kind

    # ------------------------------------------------------------------ the end

    def _finish(self) -> None:
        assert self._objects_file is not None
        self._objects_file.close()
        self._write('\n],\n"objects": [\n')
        with open(self._objects_path, encoding="utf-8") as objects:
            while chunk := objects.read(1 << 20):
                self._write(chunk)
        os.unlink(self._objects_path)
        types = {
            "objectTypes": [{"name": name, "attributes": [
                {"name": a, "type": t} for a, t in attrs.items()]}
                for name, attrs in self._object_types.items()],
            "eventTypes": [{"name": name, "attributes": [
                {"name": a, "type": t} for a, t in attrs.items()]}
                for name, attrs in self._event_types.items()],
        }
        self._write("\n],\n" + json.dumps(types, ensure_ascii=False)[1:])

    def _abandon(self) -> None:
        objects = getattr(self, "_objects_file", None)
        if objects is not None and not objects.closed:
            try:
                objects.close()
            except OSError:
                pass
        super()._abandon()
