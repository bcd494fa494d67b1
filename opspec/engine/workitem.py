"""The work item: an activity instance offered to a performer (re-exported by
:mod:`opspec.engine.performers`, where the performer protocol documents it)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from types import MappingProxyType
from typing import Any, Final

__all__ = ["WorkItem"]

_NO_DATA: Final[Mapping[str, Any]] = MappingProxyType({})
#: the fields, in ``__init__``'s order (from source, the plans make items in line:
#: ``opspec.engine.instances``' note on its tables)
FIELDS: Final = ("key", "process", "instance", "activity", "label", "participant", "lane",
                 "offered_at", "application", "data", "choices", "root_instance", "duration")


class WorkItem:
    """An activity instance offered to a performer (immutable).

    ``key`` is unique per run and identifies the offer in every call back to the session.
    ``choices`` lists alternative activity ids when the person may pick one of several
    (a deferred choice / event-based gateway); it is empty otherwise. ``duration`` is a draw
    from the activity's declared duration distribution (``None`` when it declares none), for
    performers that simulate the work (``SimulatedDevice``).

    A plain class with ``Final`` fields rather than a named tuple or a frozen dataclass, for
    speed: the engine builds one per offer (several per dose cycle of the dispenser). Compiled
    with the engine (``opspec._native``) it costs about 0.14 us to build against 1 us for a
    13-field named tuple and 2.5 us for a frozen dataclass, its fields read like a C struct's,
    and assigning one raises ``AttributeError``; from source, mypy enforces ``Final``. Its
    fields are slots: an item holds no ``__dict__`` (nor does the compiled class), which
    makes it cheaper to make from source (the plans store its fields in line).
    """

    __slots__ = ("activity", "application", "choices", "data", "duration", "instance", "key",
                 "label", "lane", "offered_at", "participant", "process", "root_instance")

    def __init__(self, key: int, process: str, instance: int, activity: str, label: str,
                 participant: str | None, lane: str | None, offered_at: float,
                 application: str | None = None, data: Mapping[str, Any] = _NO_DATA,
                 choices: Iterable[str] = (), root_instance: int | None = None,
                 duration: float | None = None) -> None:
        self.key: Final = key
        self.process: Final = process
        self.instance: Final = instance
        self.activity: Final = activity
        self.label: Final = label
        self.participant: Final = participant
        self.lane: Final = lane
        self.offered_at: Final = offered_at
        self.application: Final = application
        self.data: Final = data
        # a list from a caller too (no tuple() call for the engine's own tuples)
        self.choices: Final[tuple[str, ...]] = (
            choices if type(choices) is tuple else tuple(choices))
        self.root_instance: Final = root_instance
        self.duration: Final = duration

    def _values(self) -> tuple[Any, ...]:
        return (self.key, self.process, self.instance, self.activity, self.label,
                self.participant, self.lane, self.offered_at, self.application, self.data,
                self.choices, self.root_instance, self.duration)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, WorkItem):
            return NotImplemented
        return self._values() == other._values()

    def __repr__(self) -> str:
        fields = ", ".join(f"{name}={value!r}" for name, value in zip(FIELDS, self._values(),
                                                                       strict=True))
        return f"WorkItem({fields})"
