"""Which performer performs what: participants, lanes and applications mapped to performers.

Lookup order for a manual activity: its participant id, then its lanes (the activity's lane,
the pool lane holding its participant, the process's lane directive), then the default
device performer for activities outside the user lane. A user-lane activity with no performer
waits (and is reported as a deadlock if nothing else can happen). Automatic task activities
go to the performer bound to their Application id, if any, else complete by themselves
(instantly or after their declared duration).

Several performers may serve one Application id (two motors, each its own participant, both
offering ``drive``). The activity's Performer says which one does the work (XPDL 2.1,
WfMC-TC-1025, 7.6: "Performers ... the resource that is requested to or should perform the
activity"), so such an id is served by
:class:`SharedApplication`, which hands each work item to the performer bound to the
activity's participant or lane; it had gone, silently, to whichever was bound last.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from opspec.engine.compiled import CompiledPackage
from opspec.engine.lanes import all_activities
from opspec.engine.performers import Performer, PerformerSession, WorkItem

__all__ = ["PerformerRegistry", "SharedApplication", "spec_names"]


def spec_names(compiled: CompiledPackage) -> set[str]:
    """The participant and lane ids the activities of ``compiled`` may be performed under
    (nested blocks included): the names a performer is bound under for one participant's
    work."""
    names: set[str] = set()
    for act in all_activities(compiled):
        if act.participant is not None:
            names.add(act.participant)
        names.update(act.lanes)
    return names


class SharedApplication:
    """One Application id served by several bound performers. A work item goes to the one
    bound to its activity's participant, else to its lane, else to the one *general* server
    (bound under no name of the spec's participants and lanes: a world's devices, a
    performer bound by Application id alone). Where none of these chooses, it fails with a
    message saying how to choose (the engine does not guess which device was meant)."""

    __slots__ = ("_session", "application", "claimed", "names", "servers")

    def __init__(self, application: str, names: Mapping[str, Performer],
                 servers: list[Performer]) -> None:
        self.application = application
        self.names = names          # the registry's own, live: bindings made later count
        self.servers = servers
        #: the spec's participant and lane ids (:meth:`PerformerRegistry.claim`)
        self.claimed: frozenset[str] = frozenset()
        self._session: PerformerSession | None = None

    def _bound_names(self, performer: Performer) -> list[str]:
        return sorted(name for name, p in self.names.items() if p is performer)

    def _server(self, item: WorkItem) -> Performer | None:
        servers = self.servers
        for name in (item.participant, item.lane):
            if name is not None:
                performer = self.names.get(name)
                if performer is not None and any(performer is s for s in servers):
                    return performer
        general = [s for s in servers
                   if not any(n in self.claimed for n in self._bound_names(s))]
        return general[0] if len(general) == 1 else None

    def attach(self, session: PerformerSession) -> None:
        # the servers are attached as performers of the registry in their own right
        self._session = session

    def offer(self, item: WorkItem) -> None:
        server = self._server(item)
        if server is not None:
            server.offer(item)
            return
        if self._session is None:
            raise RuntimeError("SharedApplication was offered work before attach()")
        bound = sorted(n for s in self.servers for n in self._bound_names(s))
        self._session.fail(
            item, "AmbiguousApplication",
            f"activity {item.activity!r}: application {self.application!r} is served by "
            f"{len(self.servers)} bound performers ({', '.join(bound) or 'bound by id'}) and "
            f"the activity's performer {item.participant!r} is none of them; give the "
            "activity the participant whose device should do it, or bind one performer to "
            "the application")

    def withdraw(self, item: WorkItem, reason: str) -> None:
        server = self._server(item)
        if server is not None:
            server.withdraw(item, reason)


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
            self.bind_application(app, performer)
        return self

    def bind_application(self, application: str, performer: Performer) -> PerformerRegistry:
        """Bind an Application id to ``performer``; a second, different performer makes the
        id a :class:`SharedApplication` (the activity's performer chooses between them)."""
        bound = self.applications.get(application)
        if bound is None or bound is performer:
            self.applications[application] = performer
        elif isinstance(bound, SharedApplication):
            if not any(performer is s for s in bound.servers):
                bound.servers.append(performer)
        else:
            self.applications[application] = SharedApplication(
                application, self.names, [bound, performer])
        return self

    def claim(self, compiled: CompiledPackage) -> None:
        """Tell the shared Application ids which bound names are the participants and lanes
        of ``compiled`` (the simulation does, once, before its performers are attached): a
        performer bound under one of them does that participant's work, not another's."""
        shared = [b for b in self.applications.values() if isinstance(b, SharedApplication)]
        if shared:
            claimed = frozenset(spec_names(compiled))
            for bound in shared:
                bound.claimed = claimed

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
        served = [p for bound in self.applications.values()
                  for p in (bound.servers if isinstance(bound, SharedApplication) else [bound])]
        shared = [p for p in self.applications.values() if isinstance(p, SharedApplication)]
        for performer in [*self.names.values(), *served, *shared,
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
