"""Soundness of a process's control flow: a bounded token game with data abstracted away.

Each process level (the process, and each activity set on its own) is read as a net whose
places are its transitions (plus one start place per start activity) and whose moves are its
activities:

- **joins**: XOR (and no restriction) fires on one token of any incoming transition; AND needs
  a token on every incoming transition; OR fires on the tokens present when no other token can
  still reach one of its empty inputs (the usual "nothing more can arrive" rule, decided on the
  graph);
- **splits**: AND puts a token on every normal outgoing transition; XOR and event-based
  gateways take one — any CONDITION transition may be the one (data is abstracted), an
  unconditional transition is always true so later ones are never reached, OTHERWISE when no
  unconditional one precedes it; OR takes any non-empty subset;
- **exceptions**: an activity with EXCEPTION/DEFAULTEXCEPTION transitions (deadlines, faults)
  may end along any one of them instead; a boundary event may interrupt its host;
- an activity with no normal outgoing transition ends its token; the instance completes
  properly when no token is left.

Breadth-first exploration from the start, up to ``max_states`` markings, with parents kept so
every problem comes with the shortest witness (the activities fired). Reported: deadlocks
(tokens left, nothing can fire, no end reached), improper completion (an end reached, tokens
stuck), livelocks (reachable markings that can neither complete nor deadlock: an endless loop),
dead activities, AND-joins that can never fire, and unbounded places. Plus the package's XPDL
graph conformance class: LOOP_BLOCKED forbids cycles; FULL_BLOCKED also wants every split
closed by a join of the same kind.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from itertools import combinations

from opspec.model.activities import Activity, GatewayType, Route
from opspec.model.graph import EXCEPTION_KINDS, FlowGraph, attached_to, levels
from opspec.model.process import ConditionKind, WorkflowProcess

__all__ = ["Problem", "SoundnessReport", "check_process"]

TOKEN_BOUND = 4          # more tokens than this on one place: unbounded


@dataclass(frozen=True, slots=True)
class Problem:
    """One soundness problem: ``kind`` is deadlock, improper-completion, livelock, dead,
    and-join-never-fires, unbounded, or conformance; ``witness`` the activities fired (or the
    cycle / unmatched split for conformance)."""

    kind: str
    process: str
    activity: str | None
    message: str
    witness: tuple[str, ...] = ()
    line: int | None = None


@dataclass(frozen=True, slots=True)
class SoundnessReport:
    process: str
    states: int
    complete: bool                  # False: the state space exceeded max_states
    problems: tuple[Problem, ...]

    @property
    def sound(self) -> bool:
        return self.complete and not self.problems


def _join(activity: Activity) -> GatewayType:
    if activity.join is not None:
        return activity.join.type
    return GatewayType.XOR


def _split(activity: Activity) -> GatewayType:
    if activity.split is not None:
        return activity.split.type
    if isinstance(activity.body, Route) and activity.body.gateway is GatewayType.EVENT:
        return GatewayType.EVENT
    return GatewayType.XOR


class _Net:
    def __init__(self, graph: FlowGraph, starts: tuple[str, ...]) -> None:
        self.graph = graph
        self.places: list[str] = [f"start:{s}" for s in starts] + [
            t.id or f"{t.source}->{t.target}#{n}" for n, t in enumerate(graph.transitions)]
        self.start_place = {s: n for n, s in enumerate(starts)}
        offset = len(starts)
        self.inputs: dict[str, list[int]] = {a: [] for a in graph.by_id}
        self.normal_out: dict[str, list[tuple[int, ConditionKind]]] = {a: [] for a in graph.by_id}
        self.exception_out: dict[str, list[int]] = {a: [] for a in graph.by_id}
        for n, transition in enumerate(graph.transitions):
            place = offset + n
            self.inputs[transition.target].append(place)
            kind = transition.condition.kind
            if kind in EXCEPTION_KINDS:
                self.exception_out[transition.source].append(place)
            else:
                self.normal_out[transition.source].append((place, kind))
        for activity, place in self.start_place.items():
            self.inputs[activity].insert(0, place)
        # a boundary event interrupting its host gets a place of its own, filled by the host
        self.boundary_place: dict[str, int] = {}
        for events in graph.boundary.values():
            for event in events:
                self.places.append(f"boundary:{event}")
                self.boundary_place[event] = len(self.places) - 1
                self.inputs[event].append(len(self.places) - 1)
        self.place_target: dict[int, str] = {}
        for activity, places in self.inputs.items():
            for place in places:
                self.place_target[place] = activity
        self.reach = {a: graph.reachable([a]) for a in graph.by_id}

    def initial(self) -> tuple[int, ...]:
        marking = [0] * len(self.places)
        for place in self.start_place.values():
            marking[place] = 1
        return tuple(marking)

    def _or_enabled(self, activity: str, marking: tuple[int, ...]) -> bool:
        inputs = self.inputs[activity]
        if not any(marking[p] for p in inputs):
            return False
        empty = [p for p in inputs if not marking[p]]
        if not empty:
            return True
        # another token that can still reach this join through one of its empty inputs
        for place, count in enumerate(marking):
            if count and place not in inputs:
                holder = self.place_target.get(place)
                if holder is not None and activity in self.reach.get(holder, ()):
                    return False
        return True

    def firings(self, marking: tuple[int, ...]) -> Iterator[tuple[str, tuple[int, ...], bool]]:
        """(activity, next marking, ended) for every possible move."""
        for activity_id, inputs in self.inputs.items():
            if not inputs:
                continue
            activity = self.graph.by_id[activity_id]
            join = _join(activity)
            if join is GatewayType.AND:
                if not all(marking[p] for p in inputs):
                    continue
                consumed = [inputs]
            elif join is GatewayType.OR:
                if not self._or_enabled(activity_id, marking):
                    continue
                consumed = [[p for p in inputs if marking[p]]]
            else:
                consumed = [[p] for p in inputs if marking[p]]
            for take in consumed:
                base = list(marking)
                for place in take:
                    base[place] -= 1
                for produced in self._outcomes(activity):
                    after = base.copy()
                    for place in produced:
                        after[place] += 1
                    yield activity_id, tuple(after), not produced

    def _outcomes(self, activity: Activity) -> Iterator[tuple[int, ...]]:
        normal = self.normal_out[activity.id]
        split = _split(activity)
        if (activity.split is None and not isinstance(activity.body, Route) and len(normal) > 1
                and all(kind is ConditionKind.NONE for _, kind in normal)):
            # several unconditional flows out of a plain activity: parallel (BPMN reading)
            split = GatewayType.AND
        if not normal:
            yield ()
        elif split is GatewayType.AND:
            yield tuple(p for p, _ in normal)
        elif split is GatewayType.OR:
            places = [p for p, _ in normal]
            for size in range(1, len(places) + 1):
                yield from combinations(places, size)
        else:
            # data is abstracted: any branch of an exclusive split may be the one taken
            for place, _kind in normal:
                yield (place,)
        for place in self.exception_out[activity.id]:
            yield (place,)
        for event in self.graph.boundary.get(activity.id, ()):
            yield (self.boundary_place[event],)


def _line(graph: FlowGraph, activity: str | None) -> int | None:
    if activity is None or activity not in graph.by_id:
        return None
    location = graph.by_id[activity].location
    return location.line if location is not None else None


def check_level(process: str, graph: FlowGraph, starts: tuple[str, ...], *,
                max_states: int = 100_000) -> SoundnessReport:
    net = _Net(graph, starts)
    start = net.initial()
    parents: dict[tuple[tuple[int, ...], bool], tuple[tuple[tuple[int, ...], bool], str] | None]
    first = (start, False)
    parents = {first: None}
    edges: dict[tuple[tuple[int, ...], bool], list[tuple[tuple[int, ...], bool]]] = {}
    queue = deque([first])
    fired: set[str] = set()
    problems: list[Problem] = []
    complete = True
    unbounded_reported: set[int] = set()

    def witness(state: tuple[tuple[int, ...], bool]) -> tuple[str, ...]:
        path: list[str] = []
        node = parents.get(state)
        while node is not None:
            previous, activity = node
            path.append(activity)
            node = parents.get(previous)
        return tuple(reversed(path))

    dead_states: list[tuple[tuple[int, ...], bool]] = []
    while queue:
        state = queue.popleft()
        marking, ended = state
        moves = list(net.firings(marking))
        edges[state] = []
        if not moves and any(marking):
            dead_states.append(state)
        for activity, after, finished in moves:
            fired.add(activity)
            nxt = (after, ended or finished)
            edges[state].append(nxt)
            over = next((p for p, c in enumerate(after) if c > TOKEN_BOUND), None)
            if over is not None:
                if over not in unbounded_reported:
                    unbounded_reported.add(over)
                    target = net.place_target.get(over)
                    problems.append(Problem(
                        "unbounded", process, target,
                        f"tokens pile up before {target!r} (more than {TOKEN_BOUND}): the "
                        "flow creates tokens faster than they are consumed",
                        (*witness(state), activity), _line(graph, target)))
                continue
            if nxt not in parents:
                if len(parents) >= max_states:
                    complete = False
                    continue
                parents[nxt] = (state, activity)
                queue.append(nxt)
    for state in dead_states:
        marking, ended = state
        waiting = sorted({net.place_target[p] for p, c in enumerate(marking)
                          if c and p in net.place_target})
        kind = "improper-completion" if ended else "deadlock"
        what = ("the process reached an end but tokens are left behind at"
                if ended else "deadlock: nothing can fire, tokens wait at")
        problems.append(Problem(kind, process, waiting[0] if waiting else None,
                                f"{what} {', '.join(waiting)}", witness(state),
                                _line(graph, waiting[0] if waiting else None)))
    if complete:
        # livelock: states that can neither complete (empty marking) nor reach a dead state
        good = {s for s in parents if not any(s[0])} | set(dead_states)
        backward: dict[tuple[tuple[int, ...], bool], list[tuple[tuple[int, ...], bool]]] = {}
        for source, targets in edges.items():
            for target in targets:
                backward.setdefault(target, []).append(source)
        stack = list(good)
        settled = set(good)
        while stack:
            node = stack.pop()
            for source in backward.get(node, ()):
                if source not in settled:
                    settled.add(source)
                    stack.append(source)
        stuck = [s for s in parents if s not in settled]
        if stuck:
            state = min(stuck, key=lambda s: len(witness(s)))
            active = sorted({net.place_target[p] for p, c in enumerate(state[0])
                             if c and p in net.place_target})
            problems.append(Problem(
                "livelock", process, active[0] if active else None,
                f"livelock: from here the process can never complete (an endless loop "
                f"through {', '.join(active)})", witness(state),
                _line(graph, active[0] if active else None)))
        for activity in graph.by_id.values():
            if activity.id in fired or attached_to(activity):
                continue
            is_and = _join(activity) is GatewayType.AND and len(net.inputs[activity.id]) > 1
            problems.append(Problem(
                "and-join-never-fires" if is_and else "dead", process, activity.id,
                (f"AND-join {activity.id!r} can never fire: its incoming branches never all "
                 "hold a token together") if is_and else
                f"activity {activity.id!r} can never run", (), _line(graph, activity.id)))
    return SoundnessReport(process, len(parents), complete, tuple(problems))


def _conformance(process: WorkflowProcess, graph: FlowGraph, klass: str) -> list[Problem]:
    problems: list[Problem] = []
    if klass not in ("LOOP_BLOCKED", "FULL_BLOCKED"):
        return problems
    cycle = graph.find_cycle()
    if cycle is not None:
        problems.append(Problem(
            "conformance", process.id, cycle[0],
            f"the package declares GraphConformance {klass}, but the process has a cycle: "
            f"{' -> '.join(cycle)}", cycle, _line(graph, cycle[0])))
    if klass == "FULL_BLOCKED":
        for activity in graph.by_id.values():
            normal = [t for t in graph.outgoing[activity.id]
                      if t.condition.kind not in EXCEPTION_KINDS]
            if len(normal) < 2:
                continue
            kind = _split(activity)
            branches = [graph.reachable([t.target]) for t in normal]
            common = frozenset.intersection(*branches)
            join = next((a for a in graph.by_id if a in common and len(graph.incoming[a]) > 1),
                        None)
            if join is None or _join(graph.by_id[join]) is not (
                    GatewayType.XOR if kind is GatewayType.EVENT else kind):
                problems.append(Problem(
                    "conformance", process.id, activity.id,
                    f"FULL_BLOCKED: the {kind.value} split {activity.id!r} is not closed by a "
                    f"{kind.value} join" + (f" (its branches meet at {join!r})" if join else ""),
                    (activity.id,), _line(graph, activity.id)))
    return problems


def check_process(process: WorkflowProcess, *, conformance: str | None = None,
                  max_states: int = 100_000) -> list[SoundnessReport]:
    """A report per level of ``process`` (the process, then each activity set)."""
    reports = []
    for activity_set, graph in levels(process):
        name = process.id if activity_set is None else f"{process.id}/{activity_set.id}"
        starts = graph.starts()
        report = check_level(name, graph, starts, max_states=max_states)
        extra = _conformance(process, graph, conformance or "")
        if extra:
            report = SoundnessReport(report.process, report.states, report.complete,
                                     report.problems + tuple(extra))
        reports.append(report)
    return reports

