"""Case notions for exported traces: what one process-mining case is.

One simulated user's trace interleaves many workflow instances. A process-mining tool needs it
cut into cases, and which cut is right depends on the question:

- ``user``: everything one simulated user's run did (all days) is one case — for questions
  about a user over time;
- ``instance``: each workflow instance is a case (``notify_workflow#2``) — one process at a
  time, as a workflow engine's log has it;
- ``chain`` (the default): each *chain* is a case: an instance started by a timer or by
  nothing (a root), with every instance it set in motion, recursively — the subflows it called
  or started, and the instances started by the messages and signals it raised. A case is named
  after the spec's own root workflow (``A/3/timer_workflow#14``): for the medication dispenser
  one chain is one dose (the timer's firing, its notify and schedule instances, and the user's
  responses to each alarm), for a stove guard one cooking session. Many short cases that
  each run the device's process once are what a process-discovery algorithm (the inductive
  or alpha miner) learns a model from; one case per user would be one long trace of every
  day. ``dose``, the notion's earlier name, is read as ``chain``.

Who set an instance in motion is read from the trace itself (``process.started`` carries
``parent`` for a called subflow and ``trigger`` for the rest): a started subflow's cause is
the instance whose activity of that name started last; a message or signal start's cause is
the instance that raised that trigger last. Nothing about the spec is needed.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

__all__ = ["ALIASES", "CASE_NOTIONS", "ChainTracker", "split_cases"]

#: The case notions, in the words of ``opspec evaluate --case``; the default is ``chain``.
CASE_NOTIONS = ("user", "instance", "chain")
#: Earlier names of case notions (runs stored with them resume as before).
ALIASES = {"dose": "chain"}


@dataclass(slots=True)
class ChainTracker:
    """Follows one run's events and tells, for each workflow instance, the root instance of
    its chain (see the module docstring). Feed every event, in trace order, to
    :meth:`see` before asking :meth:`root` about it."""

    _root: dict[int, int] = field(default_factory=dict)        # instance -> root instance
    _process: dict[int, str] = field(default_factory=dict)     # instance -> process id
    _raised: dict[str, int] = field(default_factory=dict)      # trigger name -> instance
    _started: dict[str, int] = field(default_factory=dict)     # activity id -> instance

    def see(self, event: Any) -> None:
        kind = event.kind
        instance = event.instance
        if kind == "process.started" and instance is not None:
            data = event.data or {}
            parent = data.get("parent")
            cause: int | None = parent if isinstance(parent, int) else None
            trigger = str(data.get("trigger") or "")
            if cause is None and trigger:
                how, _, name = trigger.partition(":")
                if how == "subflow":
                    cause = self._started.get(name)
                elif how in ("message", "signal"):
                    cause = self._raised.get(name)
            self._process[instance] = event.process or "?"
            self._root[instance] = (self._root.get(cause, cause) if cause is not None
                                    else instance)
        elif kind == "activity.started" and event.activity is not None and instance is not None:
            self._started[event.activity] = instance
        elif kind == "trigger.raised" and instance is not None:
            raised = (event.data or {}).get("name")
            if raised:
                self._raised[str(raised)] = instance

    def root(self, instance: int | None) -> int | None:
        """The root instance of ``instance``'s chain (None for events of no instance)."""
        if instance is None:
            return None
        return self._root.get(instance, instance)

    def name(self, instance: int) -> str:
        """``process#instance`` of an instance seen starting."""
        return f"{self._process.get(instance, '?')}#{instance}"


def _instance_of(event: Any) -> int | None:
    if event.instance is not None:
        return int(event.instance)
    found = (event.data or {}).get("instance")        # user.* events name it in their data
    return int(found) if isinstance(found, int) else None


def split_cases(events: Iterable[Any], notion: str) -> Iterator[tuple[str | None, list[Any]]]:
    """One user's events cut into cases: ``(suffix, events)`` in the order each case first
    appears, ``suffix`` naming the case within the user (``notify_workflow#2``; None for the
    ``user`` notion, whose one case is the whole trace). Events of no instance (run start
    and end) belong to no case under ``instance`` and ``chain`` and are left out."""
    notion = ALIASES.get(notion, notion)
    if notion == "user":
        yield None, list(events)
        return
    if notion not in CASE_NOTIONS:
        raise ValueError(f"unknown case notion {notion!r}")
    chains = ChainTracker()
    cases: dict[int, list[Any]] = {}
    for event in events:
        chains.see(event)
        instance = _instance_of(event)
        if instance is None:
            continue
        key = chains.root(instance) if notion == "chain" else instance
        assert key is not None
        cases.setdefault(key, []).append(event)
    for key, grouped in cases.items():
        yield chains.name(key), grouped
