"""Which performer performs what: participants, lanes and applications mapped to performers.

Lookup order for a manual activity: its participant id, then its lanes (the activity's lane,
the pool lane holding its participant, the process's lane directive), then the default
device performer for activities outside the user lane. A user-lane activity with no performer
waits (and is reported as a deadlock if nothing else can happen). Automatic task activities
go to the performer bound to their Application id, if any, else complete by themselves
(instantly or after their declared duration).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from opspec.engine.performers import Performer

__all__ = ["PerformerRegistry"]


class PerformerRegistry:
    """Bindings of names to :class:`~opspec.engine.performers.Performer` objects."""

    __slots__ = ("applications", "default_device", "names")

    def __init__(self, bindings: Mapping[str, Performer] | None = None, *,
                 default_device: Performer | None = None) -> None:
        self.names: dict[str, Performer] = {}
        self.applications: dict[str, Performer] = {}
        self.default_device = default_device
        for name, performer in (bindings or {}).items():
            self.bind(name, performer)

    def bind(self, name: str, performer: Performer) -> PerformerRegistry:
        """Bind a participant id or lane name (id or name) to ``performer``.

        A performer with an ``applications`` mapping (``CallablePerformer``) is also bound to
        each of those Application ids.
        """
        self.names[name] = performer
        for app in getattr(performer, "applications", {}) or {}:
            self.applications[app] = performer
        return self

    def bind_application(self, application: str, performer: Performer) -> PerformerRegistry:
        self.applications[application] = performer
        return self

    def lookup(self, participant: str | None, lanes: tuple[str, ...]) -> Performer | None:
        if participant is not None:
            performer = self.names.get(participant)
            if performer is not None:
                return performer
        for lane in lanes:
            performer = self.names.get(lane)
            if performer is not None:
                return performer
        return None

    def performers(self) -> Iterator[Performer]:
        """Every distinct performer bound (each once, in binding order)."""
        seen: set[int] = set()
        for performer in [*self.names.values(), *self.applications.values(),
                          *([self.default_device] if self.default_device else [])]:
            if id(performer) not in seen:
                seen.add(id(performer))
                yield performer

    @classmethod
    def coerce(cls, value: PerformerRegistry | Mapping[str, Performer] | None
               ) -> PerformerRegistry:
        if isinstance(value, PerformerRegistry):
            return value
        return cls(value)
