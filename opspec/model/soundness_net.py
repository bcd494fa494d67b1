"""The token game of one process level, as the engine plays it with data abstracted away.

Places are the level's transitions, plus one start place per start activity, one place per
boundary event, and for each complex join a *ready* place and one *owed* flag per incoming
transition; moves are activity firings. A marking is sparse: the (place, tokens) pairs of its
marked places, so a state costs memory in proportion to its tokens, not to the size of the
process. The rules are the engine's (:mod:`opspec.engine.interpreter`, as
:mod:`opspec.engine.compiled` classifies each activity), except that a CONDITION may be true
or false:

- **joins** apply to an activity with more than one incoming transition (as in the engine).
  XOR (and none) fires on one token of any incoming transition; AND needs a token on every
  incoming transition and consumes one from each; OR fires, consuming every token at its
  inputs, when no token elsewhere is held by an activity upstream of it (the engine's
  "nothing more can arrive upstream" rule, decided on the graph). A start activity is started
  directly, whatever its join (the engine's ``_start_at``);
- **COMPLEX joins** (BPMN 2.0 §13.4.4, as ``_complex_arrival`` runs them): each arriving token
  is counted at its incoming transition; when the IncomingCondition holds over
  ``activationCount`` (the number of incoming transitions with a token) the join fires,
  consuming a token from each transition that has one and *owing* the others: until a token
  has come (and been ignored) on each owed transition it does not fire again. Arrivals are
  processed as part of the move that produces them, in transition order. The condition is
  evaluated exactly when it reads nothing but ``activationCount`` and constants; if it reads
  data, both outcomes are played;
- **splits**, classified like the compiler: a declared AND split, or no split with several
  normal transitions all unconditional and no OTHERWISE, takes every unconditional
  transition plus any subset of the conditional ones; a declared OR or COMPLEX split, or no
  split with several normal transitions of which some are conditional (BPMN's conditional
  sequence flows: inclusive), takes every unconditional one plus any subset of the conditional
  ones; when the subset is empty, the OTHERWISE transition, else (no split, or an AND split)
  the path ends there, else the engine aborts the instance, which is not a token move and is
  left to the validator. An XOR split (and a single conditional transition) takes any one
  normal transition, OTHERWISE included; a single conditional transition with no split may
  also end the path. An *unconditional* transition of an XOR split counts as possibly taken
  too, although the engine always takes the first one: tool exports write conditions the
  designer has not filled in yet (``<Condition Type="CONDITION"><Expression/></Condition>``)
  that way, and ``opspec validate`` warns about shadowed branches
  (``unconditional-xor-branches``);
- an **event-based gateway** (a Route whose GatewayType is event-based) offers its normal
  transitions as a deferred choice: exactly one is taken, and its target is performed at once,
  without its join (the engine's ``_performed``);
- **multi-instance loops**: ``MI_FlowCondition`` All and One pass one token; Complex passes
  one token or none (its condition may never hold: the path ends); None passes one token per
  instance, each taking its own way out: as many as the ``MI_Condition`` says when it is a
  constant (up to :data:`MI_COPIES_PLAYED`), otherwise one or :data:`MI_COPIES_PLAYED`
  (instances beyond those are not played: the check's approximation);
- **exceptions**: EXCEPTION/DEFAULTEXCEPTION transitions (deadlines, faults, raised
  exceptions) are an alternative way to end the activity; an interrupting boundary event is an
  alternative way to end its host, a non-interrupting one an extra token besides it;
- an activity with no normal outgoing transition ends its token; a Terminate end event ends
  them all. Subflows, tasks, standard loops and events are one move each.
"""

from __future__ import annotations

from collections.abc import Iterator
from itertools import combinations, combinations_with_replacement

from opspec.model.activities import (
    Activity,
    Event,
    EventPosition,
    GatewayType,
    LoopKind,
    MIFlow,
    Route,
    TriggerKind,
)
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary
from opspec.model.graph import EXCEPTION_KINDS, FlowGraph
from opspec.model.process import ConditionKind, Transition

__all__ = ["MAX_CONDITIONAL_BRANCHES", "MI_COPIES_PLAYED", "Marking", "Move", "TokenNet",
           "activation_outcomes", "join_type", "split_type"]

Marking = tuple[tuple[int, int], ...]     # (place, tokens) of each marked place, by place
Move = tuple[str, Marking, bool]          # (activity fired, next marking, an end was reached)

# subsets of more conditional branches than this are not enumerated (2**n outcomes): all of
# them or none is taken instead, which keeps the joins after them honest
MAX_CONDITIONAL_BRANCHES = 8
# conditions reading more distinct atoms than this are taken as independent of each other
MAX_CONDITION_ATOMS = 8
# a multi-instance activity with MI_FlowCondition None passes a token per instance: at most
# this many are played
MI_COPIES_PLAYED = 2


def join_type(activity: Activity) -> GatewayType:
    """The declared join, XOR when none; a COMPLEX join counts as AND (for block structure:
    the check's token game plays complex joins by their own rule, see the module)."""
    if activity.join is None:
        return GatewayType.XOR
    if activity.join.type is GatewayType.COMPLEX:
        return GatewayType.AND
    return activity.join.type


def split_type(activity: Activity) -> GatewayType:
    """The declared split (an event-based gateway counts as EVENT), XOR when none."""
    if activity.split is not None:
        return activity.split.type
    if _event_gateway(activity):
        return GatewayType.EVENT
    return GatewayType.XOR


def _event_gateway(activity: Activity) -> bool:
    return isinstance(activity.body, Route) and activity.body.gateway is GatewayType.EVENT


def _ordered(activity: Activity, transitions: tuple[Transition, ...]) -> list[Transition]:
    """Outgoing transitions in the engine's order: TransitionRefs first, then file order."""
    refs = activity.split.transition_refs if activity.split is not None else ()
    if not refs:
        return list(transitions)
    rank = {ref: n for n, ref in enumerate(refs)}
    return sorted(transitions, key=lambda t: rank.get(t.id or "", len(rank)))


def _unconditional(transition: Transition) -> bool:
    """As the compiler reads it: NONE, or a CONDITION with nothing written in it."""
    condition = transition.condition
    return condition.kind is ConditionKind.NONE or (
        condition.kind is ConditionKind.CONDITION and condition.expression is None
        and not (condition.text or "").strip())


def _terminates(activity: Activity) -> bool:
    body = activity.body
    return isinstance(body, Event) and body.position is EventPosition.END and (
        (body.result or "").lower() == "terminate"
        or body.trigger.kind is TriggerKind.TERMINATE)


def _constant(expression: Expression | None, count: int) -> object:
    """The value of ``expression`` with ``activationCount`` = ``count``; ``...`` (Ellipsis)
    when it depends on anything else (data fields, calls) or cannot be decided here."""
    if isinstance(expression, Literal):
        return expression.value
    if isinstance(expression, Name):
        return count if expression.path == ("activationCount",) else ...
    if isinstance(expression, Unary):
        value = _constant(expression.operand, count)
        if value is ...:
            return ...
        if expression.op == "not":
            return not value
        return -value if isinstance(value, int | float) and not isinstance(value, bool) else ...
    if isinstance(expression, Binary):
        left = _constant(expression.left, count)
        if expression.op in ("and", "or") and left is not ...:
            if expression.op == "and" and not left:
                return left
            if expression.op == "or" and left:
                return left
            return _constant(expression.right, count)
        right = _constant(expression.right, count)
        if left is ... or right is ...:
            if expression.op == "and" and (left is not ... and not left
                                           or right is not ... and not right):
                return False
            if expression.op == "or" and (left is not ... and left
                                          or right is not ... and right):
                return True
            return ...
        numbers = all(isinstance(v, int | float) and not isinstance(v, bool)
                      for v in (left, right))
        try:
            if expression.op == "==":
                return left == right
            if expression.op == "!=":
                return left != right
            if not numbers:
                return ...
            assert isinstance(left, int | float) and isinstance(right, int | float)
            operations = {"<": left < right, "<=": left <= right, ">": left > right,
                          ">=": left >= right, "+": left + right, "-": left - right,
                          "*": left * right}
            if expression.op in operations:
                return operations[expression.op]
        except ArithmeticError:
            return ...
    return ...


_NEGATED = {">=": "<", ">": "<=", "!=": "=="}
_MIRRORED = {">": "<", ">=": "<="}


Formula = tuple[object, ...]      # ("atom", n) | ("not", f) | ("and", f, g) | ("or", f, g)


def _formula(expression: Expression | None, atoms: dict[object, int]) -> Formula:
    """``expression`` as a propositional formula over its atoms (comparisons, names, calls),
    numbered in ``atoms``: ``a >= b`` is ``not (a < b)``, ``a != b`` is ``not (a == b)``,
    ``compare(a, b) == 0`` is ``a == b``, so that complementary conditions are recognised."""
    if isinstance(expression, Unary) and expression.op == "not":
        return ("not", _formula(expression.operand, atoms))
    if isinstance(expression, Binary) and expression.op in ("and", "or"):
        return (expression.op, _formula(expression.left, atoms),
                _formula(expression.right, atoms))
    if isinstance(expression, Literal) and isinstance(expression.value, bool):
        return ("const", expression.value)
    if (isinstance(expression, Binary) and isinstance(expression.left, Call)
            and expression.left.function == "compare" and len(expression.left.args) == 2
            and expression.right == Literal(0)):
        # Java's a.compareTo(b) == 0 (or < 0, ...) is a == b (a < b, ...)
        expression = Binary(expression.op, *expression.left.args)
    if (isinstance(expression, Binary) and expression.op in ("==", "!=")
            and isinstance(expression.left, Literal)
            and not isinstance(expression.right, Literal)):
        expression = Binary(expression.op, expression.right, expression.left)
    key: object = expression if expression is not None else object()
    negate = False
    if isinstance(expression, Binary) and expression.op in _NEGATED:
        key = Binary(_NEGATED[expression.op], expression.left, expression.right)
        negate = True
    if isinstance(key, Binary) and key.op in _MIRRORED:      # a > b is b < a
        key = Binary(_MIRRORED[key.op], key.right, key.left)
    atom: Formula = ("atom", atoms.setdefault(key, len(atoms)))
    return ("not", atom) if negate else atom


def _holds(formula: Formula, values: int) -> bool:
    kind = formula[0]
    if kind == "atom":
        return bool(values >> int(formula[1]) & 1)          # type: ignore[call-overload]
    if kind == "const":
        return bool(formula[1])
    if kind == "not":
        return not _holds(formula[1], values)               # type: ignore[arg-type]
    left = _holds(formula[1], values)                       # type: ignore[arg-type]
    if kind == "and":
        return left and _holds(formula[2], values)          # type: ignore[arg-type]
    return left or _holds(formula[2], values)               # type: ignore[arg-type]


def condition_subsets(conditions: list[Expression | None]) -> list[tuple[int, ...]] | None:
    """Which of ``conditions`` may hold together (the indices of each possible set), their
    atoms taken as independent truths; ``None`` when they read too many atoms to enumerate."""
    atoms: dict[object, int] = {}
    formulas = [_formula(c, atoms) for c in conditions]
    if len(atoms) > MAX_CONDITION_ATOMS:
        return None
    # x == "yes" and x == "no" never hold together
    groups: dict[object, int] = {}
    for atom, n in atoms.items():
        if isinstance(atom, Binary) and atom.op == "==" and isinstance(atom.right, Literal):
            groups[atom.left] = groups.get(atom.left, 0) | 1 << n
    exclusive = [mask for mask in groups.values() if mask & (mask - 1)]
    found: dict[tuple[int, ...], None] = {}
    for values in range(1 << len(atoms)):
        if any((values & mask) & (values & mask) - 1 for mask in exclusive):
            continue
        found.setdefault(tuple(n for n, f in enumerate(formulas) if _holds(f, values)))
    return sorted(found, key=lambda subset: (len(subset), subset))


def activation_outcomes(activity: Activity, count: int) -> tuple[bool, ...]:
    """Whether complex join ``activity`` fires with ``count`` incoming transitions holding a
    token: ``(True,)``, ``(False,)``, or ``(True, False)`` when its IncomingCondition reads
    data (or is missing or unreadable: the engine refuses those at load)."""
    expression = activity.join.condition if activity.join is not None else None
    if expression is None:
        return (True, False)
    value = _constant(expression, count)
    if value is ...:
        return (True, False)
    return (bool(value),)


class TokenNet:
    """The places and moves of one level; :meth:`firings` lists the moves of a marking."""

    def __init__(self, graph: FlowGraph, starts: tuple[str, ...]) -> None:
        self.graph = graph
        order = {a: n for n, a in enumerate(graph.by_id)}
        self.order = order
        self.places: list[str] = [f"start:{s}" for s in starts] + [
            t.id or f"{t.source}->{t.target}#{n}" for n, t in enumerate(graph.transitions)]
        self.start_place = {s: n for n, s in enumerate(starts)}
        offset = len(starts)
        place_of = {id(t): offset + n for n, t in enumerate(graph.transitions)}
        # which activity each token place leads to
        self.place_target: dict[int, str] = {p: s for s, p in self.start_place.items()}
        for n, transition in enumerate(graph.transitions):
            self.place_target[offset + n] = transition.target
        self.inputs: dict[str, list[int]] = {a: [] for a in graph.by_id}   # transition places
        for n, transition in enumerate(graph.transitions):
            self.inputs[transition.target].append(offset + n)
        # each token of a direct place fires its activity on its own
        self.direct: dict[str, list[int]] = {a: [] for a in graph.by_id}
        for start, place in self.start_place.items():
            self.direct[start].append(place)
        self.join: dict[str, GatewayType] = {}
        performed = {place_of[id(t)] for t in graph.transitions
                     if _event_gateway(graph.by_id[t.source])
                     and t.condition.kind not in EXCEPTION_KINDS}
        for activity_id, activity in graph.by_id.items():
            inputs = self.inputs[activity_id]
            kind = activity.join.type if activity.join is not None and len(inputs) > 1 \
                else GatewayType.XOR
            self.join[activity_id] = kind
            joined = [p for p in inputs if p not in performed]
            self.direct[activity_id].extend(p for p in inputs if p in performed)
            if kind in (GatewayType.XOR, GatewayType.EVENT) or len(joined) < 2:
                self.direct[activity_id].extend(joined)
                self.join[activity_id] = GatewayType.XOR
                self.inputs[activity_id] = joined
            else:
                self.inputs[activity_id] = joined
        # a boundary event gets a place of its own, filled by its host
        self.boundary_place: dict[str, int] = {}
        for events in graph.boundary.values():
            for event in events:
                self._add_place(f"boundary:{event}", event)
                self.boundary_place[event] = len(self.places) - 1
                self.direct[event].append(len(self.places) - 1)
        # complex joins: a ready place each (the join has fired, the activity runs), then one
        # owed flag per incoming transition; flags are not tokens, and come last
        self.ready: dict[str, int] = {}
        self.slot: dict[int, tuple[str, int]] = {}       # input place -> (join, slot)
        complex_joins = [a for a, kind in self.join.items() if kind is GatewayType.COMPLEX]
        for activity_id in complex_joins:
            self._add_place(f"ready:{activity_id}", activity_id)
            self.ready[activity_id] = len(self.places) - 1
            self.direct[activity_id].append(len(self.places) - 1)
            for n, place in enumerate(self.inputs[activity_id]):
                self.slot[place] = (activity_id, n)
        self.flag_base = len(self.places)
        self.owed: dict[str, list[int]] = {}
        for activity_id in complex_joins:
            self.owed[activity_id] = []
            for place in self.inputs[activity_id]:
                self.places.append(f"owed:{activity_id}:{self.places[place]}")
                self.owed[activity_id].append(len(self.places) - 1)
        self.fires: dict[tuple[str, int], tuple[bool, ...]] = {
            (a, k): activation_outcomes(graph.by_id[a], k)
            for a in complex_joins for k in range(1, len(self.inputs[a]) + 1)}
        # OR joins wait for what is upstream of them (the activities with a path to them)
        self.upstream: dict[str, frozenset[str]] = {
            a: self._upstream(a) for a, kind in self.join.items() if kind is GatewayType.OR}
        self.terminates = {a: _terminates(act) for a, act in graph.by_id.items()}
        # (split as the engine takes it: XOR, AND or OR; whether a path may end there)
        self.split_rule: dict[str, tuple[GatewayType, bool]] = {}
        self.outcomes: dict[str, tuple[tuple[int, ...], ...]] = {
            a: tuple(dict.fromkeys(self._outcomes(act, place_of))) for a, act in
            graph.by_id.items()}

    def _add_place(self, name: str, target: str) -> None:
        self.places.append(name)
        self.place_target[len(self.places) - 1] = target

    def _upstream(self, join: str) -> frozenset[str]:
        predecessors: dict[str, set[str]] = {}
        for source in self.graph.by_id:
            for target in self.graph.successors(source):
                predecessors.setdefault(target, set()).add(source)
        seen: set[str] = set()
        stack = list(predecessors.get(join, ()))
        while stack:
            node = stack.pop()
            if node not in seen:
                seen.add(node)
                stack.extend(predecessors.get(node, ()))
        seen.discard(join)
        return frozenset(seen)

    # ------------------------------------------------------------------ markings
    def initial(self, starts: tuple[str, ...] | None = None) -> Marking:
        """A token on the start place of each of ``starts`` (default: every start)."""
        if starts is None:
            return tuple((place, 1) for place in sorted(self.start_place.values()))
        return tuple((place, 1) for place in sorted(self.start_place[s] for s in starts))

    def has_tokens(self, marking: Marking) -> bool:
        """Whether any token is left (owed flags of complex joins are not tokens)."""
        return any(place < self.flag_base for place, _ in marking)

    def token_places(self, marking: Marking) -> Iterator[tuple[int, int]]:
        return ((p, c) for p, c in marking if p < self.flag_base)

    def holders(self, marking: Marking) -> list[str]:
        """The activities tokens of ``marking`` wait at, sorted."""
        return sorted({self.place_target[p] for p, _ in self.token_places(marking)})

    # ------------------------------------------------------------------ moves
    def _or_enabled(self, activity: str, tokens: dict[int, int]) -> bool:
        inputs = self.inputs[activity]
        if not any(p in tokens for p in inputs):
            return False
        upstream = self.upstream[activity]
        # wait while a token elsewhere is held by an activity upstream of this join
        return not any(p < self.flag_base and p not in inputs
                       and self.place_target[p] in upstream for p in tokens)

    def firings(self, marking: Marking) -> Iterator[Move]:
        """Every possible move of ``marking``: (activity, next marking, an end was reached)."""
        tokens = dict(marking)
        candidates = sorted({self.place_target[p] for p in tokens if p < self.flag_base},
                            key=self.order.__getitem__)
        for activity_id in candidates:
            takes: list[list[int]] = [[p] for p in self.direct[activity_id] if p in tokens]
            join = self.join[activity_id]
            inputs = self.inputs[activity_id]
            if join is GatewayType.AND:
                if all(p in tokens for p in inputs):
                    takes.append(inputs)
            elif join is GatewayType.OR and self._or_enabled(activity_id, tokens):
                takes.append([p for p in inputs for _ in range(tokens.get(p, 0))])
            for take in takes:
                if self.terminates[activity_id]:
                    yield activity_id, tuple(sorted(
                        (p, c) for p, c in tokens.items() if p >= self.flag_base)), True
                    continue
                base = dict(tokens)
                for place in take:
                    _remove(base, place)
                for produced in self.outcomes[activity_id]:
                    for after in self._produce(base, produced):
                        yield activity_id, tuple(sorted(after.items())), not produced

    def _produce(self, base: dict[int, int], produced: tuple[int, ...]) -> list[dict[int, int]]:
        """Put a token on each place of ``produced`` in turn; tokens for a complex join
        arrive there at once (which may fire it, or not, when its condition reads data)."""
        states = [dict(base)]
        for place in produced:
            join = self.slot.get(place)
            after: list[dict[int, int]] = []
            for state in states:
                state[place] = state.get(place, 0) + 1
                if join is None:
                    after.append(state)
                else:
                    after.extend(self._arrive(state, join[0], join[1]))
            states = after
        return states

    def _arrive(self, state: dict[int, int], join: str, slot: int) -> list[dict[int, int]]:
        """A token (already on its input place) reaches complex join ``join`` on ``slot``."""
        inputs = self.inputs[join]
        owed = self.owed[join]
        if any(f in state for f in owed):
            if owed[slot] not in state:
                return [state]          # counted; the join waits for its reset
            _remove(state, inputs[slot])    # owed: this token is ignored
            del state[owed[slot]]
            if any(f in state for f in owed) or not any(p in state for p in inputs):
                return [state]
        active = sum(1 for p in inputs if p in state)
        out: list[dict[int, int]] = []
        for fires in self.fires[(join, active)]:
            if not fires:
                out.append(state)
                continue
            fired = dict(state)
            for place, flag in zip(inputs, owed, strict=True):
                if place in fired:
                    _remove(fired, place)
                else:
                    fired[flag] = 1
            ready = self.ready[join]
            fired[ready] = fired.get(ready, 0) + 1
            out.append(fired)
        return out

    # ------------------------------------------------------------------ outcomes
    def _outcomes(self, activity: Activity, place_of: dict[int, int]) -> Iterator[tuple[int, ...]]:
        """The multisets of places one firing of ``activity`` may put a token on."""
        outgoing = _ordered(activity, self.graph.outgoing[activity.id])
        normal = [(place_of[id(t)], t) for t in outgoing
                  if t.condition.kind not in EXCEPTION_KINDS]
        exceptions = [place_of[id(t)] for t in outgoing if t.condition.kind in EXCEPTION_KINDS]
        regular = [(p, _unconditional(t)) for p, t in normal
                   if t.condition.kind is not ConditionKind.OTHERWISE]
        otherwise = [p for p, t in normal if t.condition.kind is ConditionKind.OTHERWISE][:1]
        interrupting = [self.boundary_place[e] for e in self.graph.boundary.get(activity.id, ())
                        if self._interrupting(e)]
        extra = tuple(self.boundary_place[e] for e in self.graph.boundary.get(activity.id, ())
                      if not self._interrupting(e))
        declared = activity.split.type if activity.split is not None else None
        may_end = declared is None or declared is GatewayType.AND     # the engine's rule
        if declared is GatewayType.AND or (
                declared is None and len(regular) > 1 and all(u for _, u in regular)
                and not otherwise):
            split = GatewayType.AND
        elif declared in (GatewayType.OR, GatewayType.COMPLEX) or (
                declared is None and len(regular) + len(otherwise) > 1):
            split = GatewayType.OR
        else:
            split = GatewayType.XOR
        self.split_rule[activity.id] = (split, may_end)
        ways: list[tuple[int, ...]]
        if _event_gateway(activity):
            # a deferred choice among the normal transitions (OTHERWISE is not offered)
            ways = [(p,) for p, _ in regular]
        elif not normal:
            ways = [()]
        elif split in (GatewayType.AND, GatewayType.OR):
            always = [p for p, certain in regular if certain]
            maybe = [p for p, certain in regular if not certain]
            conditions = [t.condition.expression for _, t in normal
                          if t.condition.kind is not ConditionKind.OTHERWISE
                          and not _unconditional(t)]
            subsets: list[tuple[int, ...]]
            held = condition_subsets(conditions)
            if held is not None:
                # conditions over the same data are correlated: x and !x never both hold
                subsets = [tuple(maybe[n] for n in subset) for subset in held]
            elif len(maybe) > MAX_CONDITIONAL_BRANCHES:
                subsets = [(), tuple(maybe)]
            else:
                subsets = [c for size in range(len(maybe) + 1)
                           for c in combinations(maybe, size)]
            ways = []
            for chosen in subsets:
                taken = (*always, *chosen)
                if taken:
                    ways.append(taken)
                elif otherwise:
                    ways.append((otherwise[0],))
                elif may_end:
                    ways.append(())          # nothing holds: this path ends
        else:
            # XOR, deferred choice: any one branch (see the module docstring)
            ways = [(p,) for p, _ in regular]
            ways.extend((p,) for p in otherwise)
            if may_end and not otherwise and not any(certain for _, certain in regular):
                ways.append(())              # its condition fails: this path ends
        ways = [way + extra for way in ways]
        yield from self._instances(activity, ways)
        for place in (*exceptions, *interrupting):
            yield (place,)

    def _instances(self, activity: Activity, ways: list[tuple[int, ...]]
                   ) -> list[tuple[int, ...]]:
        """What the instances of a multi-instance activity pass on (see the module)."""
        loop = activity.loop
        if loop is None or loop.kind is not LoopKind.MULTI_INSTANCE:
            return ways
        if loop.flow is MIFlow.COMPLEX:
            return [*ways, ()] if () not in ways else ways
        if loop.flow is not MIFlow.NONE:
            return ways
        count = loop.condition.value if isinstance(loop.condition, Literal) else None
        if isinstance(count, int) and not isinstance(count, bool):
            copies = [min(max(count, 1), MI_COPIES_PLAYED)]
        else:
            copies = [1, MI_COPIES_PLAYED]
        out: list[tuple[int, ...]] = []
        for n in copies:
            for combo in combinations_with_replacement(ways, n):
                out.append(tuple(p for way in combo for p in way))
        return out

    def _interrupting(self, event: str) -> bool:
        body = self.graph.by_id[event].body
        return not isinstance(body, Event) or body.trigger.interrupting


def _remove(tokens: dict[int, int], place: int) -> None:
    count = tokens[place] - 1
    if count:
        tokens[place] = count
    else:
        del tokens[place]
