"""The token game of one process level, as the engine plays it with data abstracted away.

Places are the level's transitions, plus one start place per start activity and one place per
boundary event; moves are activity firings. The rules follow the engine
(:mod:`opspec.engine.interpreter`), except that a CONDITION may be true or false:

- **joins**: XOR (and none) fires on one token of any incoming transition; AND and COMPLEX
  need a token on every incoming transition; OR fires on the tokens present when no token
  elsewhere can still reach it (the engine's "nothing more can arrive upstream" rule, decided
  on the graph);
- **XOR splits** (also no split, with conditions), event-based gateways: any one normal
  transition, OTHERWISE included. An *unconditional* transition counts as possibly taken too,
  although the engine always takes the first one: tool exports write conditions the designer
  has not filled in yet (``<Condition Type="CONDITION"><Expression/></Condition>``) that way,
  and ``opspec validate`` already warns about shadowed branches
  (``unconditional-xor-branches``);
- **AND splits** take every unconditional transition plus any subset of the conditional ones
  (the engine takes the conditions that hold); **OR splits** any subset of their transitions;
  when the subset is empty, the OTHERWISE transition (no OTHERWISE: the engine aborts the
  instance, which is not a token move and is left to the validator);
- no split and several unconditional transitions (no OTHERWISE): all of them, as in the
  engine, except out of an XOR or event-based Route (read as a choice);
- **exceptions**: EXCEPTION/DEFAULTEXCEPTION transitions (deadlines, faults, raised
  exceptions) are an alternative way to end the activity; an interrupting boundary event is an
  alternative way to end its host, a non-interrupting one an extra token besides it;
- an activity with no normal outgoing transition ends its token; a Terminate end event ends
  them all. Subflows, tasks, loops and events are one move each.
"""

from __future__ import annotations

from collections.abc import Iterator
from itertools import combinations

from opspec.model.activities import (
    Activity,
    Event,
    EventPosition,
    GatewayType,
    Route,
    TriggerKind,
)
from opspec.model.graph import EXCEPTION_KINDS, FlowGraph
from opspec.model.process import ConditionKind, Transition

__all__ = ["MAX_CONDITIONAL_BRANCHES", "Move", "TokenNet", "join_type", "split_type"]

Marking = tuple[int, ...]
Move = tuple[str, Marking, bool]          # (activity fired, next marking, an end was reached)

# subsets of more conditional branches than this are not enumerated (2**n outcomes): all of
# them or none is taken instead, which keeps the joins after them honest
MAX_CONDITIONAL_BRANCHES = 8


def join_type(activity: Activity) -> GatewayType:
    """The join rule the engine applies (COMPLEX joins wait like AND joins)."""
    if activity.join is None:
        return GatewayType.XOR
    if activity.join.type is GatewayType.COMPLEX:
        return GatewayType.AND
    return activity.join.type


def split_type(activity: Activity) -> GatewayType:
    """The declared split (an event-based gateway counts as EVENT), XOR when none."""
    if activity.split is not None:
        return activity.split.type
    if isinstance(activity.body, Route) and activity.body.gateway is GatewayType.EVENT:
        return GatewayType.EVENT
    return GatewayType.XOR


def _ordered(activity: Activity, transitions: tuple[Transition, ...]) -> list[Transition]:
    """Outgoing transitions in the engine's order: TransitionRefs first, then file order."""
    refs = activity.split.transition_refs if activity.split is not None else ()
    if not refs:
        return list(transitions)
    rank = {ref: n for n, ref in enumerate(refs)}
    return sorted(transitions, key=lambda t: rank.get(t.id or "", len(rank)))


def _terminates(activity: Activity) -> bool:
    body = activity.body
    return isinstance(body, Event) and body.position is EventPosition.END and (
        (body.result or "").lower() == "terminate"
        or body.trigger.kind is TriggerKind.TERMINATE)


class TokenNet:
    """The places and moves of one level; :meth:`firings` lists the moves of a marking."""

    def __init__(self, graph: FlowGraph, starts: tuple[str, ...]) -> None:
        self.graph = graph
        self.places: list[str] = [f"start:{s}" for s in starts] + [
            t.id or f"{t.source}->{t.target}#{n}" for n, t in enumerate(graph.transitions)]
        self.start_place = {s: n for n, s in enumerate(starts)}
        offset = len(starts)
        place_of = {id(t): offset + n for n, t in enumerate(graph.transitions)}
        self.inputs: dict[str, list[int]] = {a: [] for a in graph.by_id}
        for n, transition in enumerate(graph.transitions):
            self.inputs[transition.target].append(offset + n)
        for activity, place in self.start_place.items():
            self.inputs[activity].insert(0, place)
        # a boundary event gets a place of its own, filled by its host
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
        self.terminates = {a: _terminates(act) for a, act in graph.by_id.items()}
        self.outcomes: dict[str, tuple[tuple[int, ...], ...]] = {
            a: tuple(dict.fromkeys(self._outcomes(act, place_of))) for a, act in
            graph.by_id.items()}

    def initial(self) -> Marking:
        marking = [0] * len(self.places)
        for place in self.start_place.values():
            marking[place] = 1
        return tuple(marking)

    def _or_enabled(self, activity: str, marking: Marking) -> bool:
        inputs = self.inputs[activity]
        if not any(marking[p] for p in inputs):
            return False
        if all(marking[p] for p in inputs):
            return True
        # wait while a token elsewhere can still reach this join
        for place, count in enumerate(marking):
            if count and place not in inputs:
                holder = self.place_target.get(place)
                if holder is not None and activity in self.reach.get(holder, ()):
                    return False
        return True

    def firings(self, marking: Marking) -> Iterator[Move]:
        """Every possible move of ``marking``: (activity, next marking, an end was reached)."""
        for activity_id, inputs in self.inputs.items():
            if not inputs:
                continue
            join = join_type(self.graph.by_id[activity_id])
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
                if self.terminates[activity_id]:
                    yield activity_id, (0,) * len(marking), True
                    continue
                base = list(marking)
                for place in take:
                    base[place] -= 1
                for produced in self.outcomes[activity_id]:
                    after = base.copy()
                    for place in produced:
                        after[place] += 1
                    yield activity_id, tuple(after), not produced

    def _outcomes(self, activity: Activity, place_of: dict[int, int]) -> Iterator[tuple[int, ...]]:
        """The sets of places one firing of ``activity`` may put a token on."""
        outgoing = _ordered(activity, self.graph.outgoing[activity.id])
        normal = [(place_of[id(t)], t.condition.kind) for t in outgoing
                  if t.condition.kind not in EXCEPTION_KINDS]
        exceptions = [place_of[id(t)] for t in outgoing if t.condition.kind in EXCEPTION_KINDS]
        regular = [(p, k) for p, k in normal if k is not ConditionKind.OTHERWISE]
        otherwise = [p for p, k in normal if k is ConditionKind.OTHERWISE][:1]
        split = split_type(activity)
        exclusive_route = isinstance(activity.body, Route) and activity.body.gateway in (
            GatewayType.XOR, GatewayType.EVENT)
        if (activity.split is None and not exclusive_route and len(regular) > 1
                and all(k is ConditionKind.NONE for _, k in regular) and not otherwise):
            # several unconditional flows and no split: all of them, as the engine does (an
            # XOR gateway drawn without TransitionRestrictions is still read as a choice)
            split = GatewayType.AND
        interrupting = [self.boundary_place[e] for e in self.graph.boundary.get(activity.id, ())
                        if self._interrupting(e)]
        extra = tuple(self.boundary_place[e] for e in self.graph.boundary.get(activity.id, ())
                      if not self._interrupting(e))
        normal_ways: list[tuple[int, ...]]
        if not normal:
            normal_ways = [()]
        elif split in (GatewayType.AND, GatewayType.OR):
            # AND: unconditional flows always; OR: every regular flow may hold (see above)
            certain = ConditionKind.NONE if split is GatewayType.AND else None
            always = [p for p, k in regular if k is certain]
            maybe = [p for p, k in regular if k is not certain]
            subsets: list[tuple[int, ...]]
            if len(maybe) > MAX_CONDITIONAL_BRANCHES:
                subsets = [(), tuple(maybe)]
            else:
                subsets = [c for size in range(len(maybe) + 1)
                           for c in combinations(maybe, size)]
            normal_ways = []
            for chosen in subsets:
                taken = (*always, *chosen)
                if taken:
                    normal_ways.append(taken)
                elif otherwise:
                    normal_ways.append((otherwise[0],))
        else:
            # XOR, event-based, deferred choice: any one branch (see the module docstring)
            normal_ways = [(p,) for p, _ in regular]
            normal_ways.extend((p,) for p in otherwise)
        for way in normal_ways:
            yield way + extra
        for place in (*exceptions, *interrupting):
            yield (place,)

    def _interrupting(self, event: str) -> bool:
        body = self.graph.by_id[event].body
        return not isinstance(body, Event) or body.trigger.interrupting
