"""The flow graph of one process level (a process's top-level activities, or one activity set).

Pure functions over the immutable model, shared by the structural checks
(:mod:`opspec.model.checks`) and the Graphviz writer. Activity ids are scoped per process and
per activity set, so a :class:`FlowGraph` only ever holds one level; transitions whose ends are
not activities of that level are kept aside in :attr:`FlowGraph.dangling` (the checks report
them) and take no part in the analyses.

Boundary events (intermediate events ``attached_to`` an activity) are reached through their host
activity: the graph has an implicit edge from the host to each of its boundary events.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from opspec.model.activities import Activity, Event, EventPosition, GatewayType, Route
from opspec.model.process import ActivitySet, ConditionKind, Transition, WorkflowProcess

__all__ = [
    "AndJoinDeadlock",
    "FlowGraph",
    "and_join_deadlocks",
    "is_exclusive_split",
    "levels",
]

NORMAL_KINDS = frozenset({ConditionKind.NONE, ConditionKind.CONDITION, ConditionKind.OTHERWISE})
EXCEPTION_KINDS = frozenset({ConditionKind.EXCEPTION, ConditionKind.DEFAULTEXCEPTION})


def _freeze(groups: dict[str, list[Transition]]) -> Mapping[str, tuple[Transition, ...]]:
    return MappingProxyType({key: tuple(value) for key, value in groups.items()})


@dataclass(frozen=True, slots=True)
class FlowGraph:
    """Adjacency of one process level.

    ``outgoing``/``incoming`` map every activity id to its transitions (in file order);
    ``dangling`` holds the transitions with an end that is not an activity of this level;
    ``transition_by_id`` maps the Id of each transition of the level, dangling ones included,
    to it (the last one when Ids are duplicated), built once so that the checks of each split's
    TransitionRefs stay linear. When ids are duplicated, the first activity with an id wins.
    """

    activities: tuple[Activity, ...]
    transitions: tuple[Transition, ...]
    dangling: tuple[Transition, ...]
    by_id: Mapping[str, Activity]
    outgoing: Mapping[str, tuple[Transition, ...]]
    incoming: Mapping[str, tuple[Transition, ...]]
    boundary: Mapping[str, tuple[str, ...]]
    transition_by_id: Mapping[str, Transition] = field(
        default_factory=lambda: MappingProxyType({}))

    @classmethod
    def of(cls, activities: Iterable[Activity], transitions: Iterable[Transition]) -> FlowGraph:
        acts = tuple(activities)
        by_id: dict[str, Activity] = {}
        for activity in acts:
            by_id.setdefault(activity.id, activity)
        outgoing: dict[str, list[Transition]] = {key: [] for key in by_id}
        incoming: dict[str, list[Transition]] = {key: [] for key in by_id}
        kept: list[Transition] = []
        dangling: list[Transition] = []
        named: dict[str, Transition] = {}
        for transition in transitions:
            named[transition.id] = transition
            if transition.source in by_id and transition.target in by_id:
                kept.append(transition)
                outgoing[transition.source].append(transition)
                incoming[transition.target].append(transition)
            else:
                dangling.append(transition)
        boundary: dict[str, list[str]] = {}
        for activity in by_id.values():
            host = attached_to(activity)
            if host is not None and host in by_id:
                boundary.setdefault(host, []).append(activity.id)
        return cls(
            activities=acts,
            transitions=tuple(kept),
            dangling=tuple(dangling),
            by_id=MappingProxyType(by_id),
            outgoing=_freeze(outgoing),
            incoming=_freeze(incoming),
            boundary=MappingProxyType({k: tuple(v) for k, v in boundary.items()}),
            transition_by_id=MappingProxyType(named),
        )

    def successors(self, activity_id: str) -> tuple[str, ...]:
        """Targets of the activity's transitions, then its boundary events (no duplicates)."""
        out = [t.target for t in self.outgoing.get(activity_id, ())]
        out.extend(self.boundary.get(activity_id, ()))
        return tuple(dict.fromkeys(out))

    def starts(self, start_activity: str | None = None) -> tuple[str, ...]:
        """Where an instance of this level starts, as the engine decides it.

        ``start_activity`` (a BlockActivity's StartActivityId) wins when it names an activity
        of the level; otherwise every activity without incoming transitions that is not a
        boundary event, in file order; where there is none (a cycle), the activities marked
        StartActivity="true" (XPDL: "Used when there is no other way to determine this").
        """
        if start_activity is not None and start_activity in self.by_id:
            return (start_activity,)
        natural = tuple(
            key for key, activity in self.by_id.items()
            if not self.incoming[key] and (attached_to(activity) or "") not in self.by_id
        )
        return natural or tuple(key for key, activity in self.by_id.items()
                                if activity.marked_start)

    def reachable(self, sources: Iterable[str], *, avoid: Iterable[str] = ()) -> frozenset[str]:
        """Activities reachable from ``sources`` (included) without entering ``avoid``."""
        blocked = frozenset(avoid)
        seen: set[str] = set()
        stack = [s for s in sources if s in self.by_id and s not in blocked]
        outgoing, boundary = self.outgoing, self.boundary
        while stack:
            node = stack.pop()
            if node in seen:
                continue
            seen.add(node)
            # the successors (as successors() gives them), without a tuple per node
            for transition in outgoing.get(node, ()):
                target = transition.target
                if target not in seen and target not in blocked:
                    stack.append(target)
            for target in boundary.get(node, ()):
                if target not in seen and target not in blocked:
                    stack.append(target)
        return frozenset(seen)

    def reachable_for_sure(self, source: str, *, avoid: Iterable[str] = ()) -> frozenset[str]:
        """Activities a token leaving ``source`` certainly reaches (``source`` included):
        follows unconditional transitions out of activities that are not exclusive splits,
        without entering ``avoid``."""
        blocked = frozenset(avoid)
        seen: set[str] = set()
        stack = [source] if source in self.by_id and source not in blocked else []
        while stack:
            node = stack.pop()
            if node in seen:
                continue
            seen.add(node)
            if is_exclusive_split(self.by_id[node]):
                continue
            stack.extend(t.target for t in self.outgoing[node]
                         if t.condition.kind is ConditionKind.NONE and t.target not in blocked)
        return frozenset(seen)

    def find_cycle(self) -> tuple[str, ...] | None:
        """One cycle of activity ids (first node repeated at the end), or ``None``.

        Iterative depth-first search, so deep graphs cannot exhaust the Python stack.
        """
        state: dict[str, int] = {}       # 1 = on the stack, 2 = finished
        for root in self.by_id:
            if root in state:
                continue
            path: list[str] = [root]
            iters = [iter(self.successors(root))]
            state[root] = 1
            while iters:
                nxt = next(iters[-1], None)
                if nxt is None:
                    state[path.pop()] = 2
                    iters.pop()
                    continue
                mark = state.get(nxt)
                if mark == 1:
                    return (*path[path.index(nxt):], nxt)
                if mark is None:
                    state[nxt] = 1
                    path.append(nxt)
                    iters.append(iter(self.successors(nxt)))
        return None


def attached_to(activity: Activity) -> str | None:
    """The host of a boundary event, else ``None``."""
    body = activity.body
    if isinstance(body, Event) and body.position is EventPosition.INTERMEDIATE:
        return body.trigger.attached_to
    return None


def is_exclusive_split(activity: Activity) -> bool:
    """True when completing ``activity`` takes exactly one of its normal transitions: an XOR
    (data-based) or event-based split, or an event-based gateway."""
    if activity.split is not None:
        return activity.split.type in (GatewayType.XOR, GatewayType.EVENT)
    return isinstance(activity.body, Route) and activity.body.gateway is GatewayType.EVENT


def levels(process: WorkflowProcess) -> tuple[tuple[ActivitySet | None, FlowGraph], ...]:
    """The process's top level (``None``) followed by each activity set, with their graphs."""
    out: list[tuple[ActivitySet | None, FlowGraph]] = [
        (None, FlowGraph.of(process.activities, process.transitions))]
    out.extend((s, FlowGraph.of(s.activities, s.transitions)) for s in process.activity_sets)
    return tuple(out)


@dataclass(frozen=True, slots=True)
class AndJoinDeadlock:
    """An AND-join that can wait forever because an exclusive split feeds it.

    Taking branch ``branch`` (a transition id) of the exclusive split ``split`` (an activity
    id) brings tokens to ``arrives`` (incoming transition ids of ``join``) but never to
    ``missing``. ``certain`` is False when the tokens reach ``arrives`` only through further
    conditions or exclusive splits, whose data may be correlated with the first split's (then
    the deadlock is possible, not sure).
    """

    join: str
    split: str
    branch: str
    arrives: tuple[str, ...]
    missing: tuple[str, ...]
    certain: bool = True


def and_join_deadlocks(graph: FlowGraph, starts: Iterable[str]) -> tuple[AndJoinDeadlock, ...]:
    """AND-joins whose incoming transitions are fed only through one exclusive split's branches
    such that some branch cannot reach all of them (at most one finding per join).

    For a join ``J`` with at least two incoming transitions, a candidate split ``X`` must
    dominate ``J``'s feeders: no source of an incoming transition of ``J`` is reachable from a
    start while avoiding ``X``. Each normal outgoing transition (a *branch*) of ``X`` is followed
    without passing ``X`` or ``J`` again; it *feeds* the incoming transitions of ``J`` whose
    source it reaches. If every incoming transition is fed by some branch, but one branch feeds
    only part of them, taking that branch leaves ``J`` waiting forever. Incoming transitions
    fed by no branch (loop back-edges through ``J``) make the join undecidable here: skipped.
    """
    start_ids = tuple(starts)
    found: list[AndJoinDeadlock] = []
    splits = [a.id for a in graph.by_id.values() if is_exclusive_split(a)]
    for join_id, join in graph.by_id.items():
        if join.join is None or join.join.type is not GatewayType.AND:
            continue
        incoming = graph.incoming[join_id]
        if len(incoming) < 2:
            continue
        for split_id in splits:
            finding = _deadlock_via(graph, start_ids, join_id, incoming, split_id)
            if finding is not None:
                found.append(finding)
                break
    return tuple(found)


def _deadlock_via(graph: FlowGraph, starts: tuple[str, ...], join_id: str,
                  incoming: tuple[Transition, ...], split_id: str) -> AndJoinDeadlock | None:
    if split_id == join_id:
        return None
    around = graph.reachable(starts, avoid=(split_id,))
    if any(t.source in around for t in incoming):
        return None           # some feeder is reached without the split: not "fed only by" it
    branches = [t for t in graph.outgoing[split_id] if t.condition.kind in NORMAL_KINDS]
    if len(branches) < 2:
        return None
    fed: dict[str, tuple[str, ...]] = {}
    sure: dict[str, tuple[str, ...]] = {}
    for branch in branches:
        if branch.target == join_id:
            region: frozenset[str] = frozenset()
            certain: frozenset[str] = frozenset()
        else:
            region = graph.reachable((branch.target,), avoid=(split_id, join_id))
            certain = graph.reachable_for_sure(branch.target, avoid=(split_id, join_id))
        fed[branch.id] = tuple(
            t.id for t in incoming
            if t is branch or (t.source in region and t.source != split_id))
        sure[branch.id] = tuple(
            t.id for t in incoming
            if t is branch or (t.source in certain and t.condition.kind is ConditionKind.NONE
                               and not is_exclusive_split(graph.by_id[t.source])))
    if not any(fed.values()):
        return None
    covered = {tid for ids in fed.values() for tid in ids}
    if len(covered) != len(incoming):
        return None
    possible: AndJoinDeadlock | None = None
    for branch in branches:
        arrives = fed[branch.id]
        if arrives and len(arrives) < len(incoming):
            missing = tuple(t.id for t in incoming if t.id not in arrives)
            if sure[branch.id]:
                return AndJoinDeadlock(join_id, split_id, branch.id, sure[branch.id], missing)
            possible = possible or AndJoinDeadlock(join_id, split_id, branch.id, arrives,
                                                   missing, certain=False)
    return possible
