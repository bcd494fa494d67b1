"""Soundness of a process's control flow: a bounded token game with data abstracted away.

Each process level (the process, and each activity set on its own, started where its
BlockActivity starts it) is played as a token game (:mod:`opspec.model.soundness_net` has the
rules: XOR branches and conditions may go either way, AND joins wait for every branch, OR joins
for every token that can still arrive, exceptions and boundary events are alternative ends).
A subflow, a BlockActivity, a loop or an event is one move of its level; the subflow's process
and the activity set are checked as levels of their own.

Breadth-first exploration from the start over markings (token counts per place, plus whether
an end has been reached; one root marking per kind of instance the engine starts, as
:mod:`opspec.model.instance_starts` finds them: a triggered start event's instance runs only
its path), up to ``max_states`` of them, with the parent of each kept, so every
problem comes with the shortest witness (the activities fired from the start):

- **deadlock**: tokens left, nothing can fire, no end reached;
- **improper-completion**: an end was reached, but tokens are stuck elsewhere;
- **livelock**: markings from which the process can neither complete nor get stuck (the
  option to complete is lost: an endless loop with no way out);
- **dead**: an activity that fires in no reachable marking; **and-join-never-fires**: the
  same for an AND join, saying which of its inputs ever get a token;
- **unbounded**: more than :data:`TOKEN_BOUND` tokens on one place (the exploration stops
  there, so dead activities and livelocks are not reported then);
- **conformance**: a violation of the package's graph conformance class
  (:mod:`opspec.model.soundness_conformance`);
- **zero-time-cycle** (a warning): a reachable cycle of instantaneous activities, where a
  run's clock may stop (found on the compiled package by
  :mod:`opspec.engine.zero_time_check`; ``opspec check`` adds them).

A level whose exploration stopped at ``max_states`` is *undecided* (``complete`` is False):
the problems found so far are real, but dead activities and livelocks are not reported, and
it is never called sound.
"""

from __future__ import annotations

from array import array
from dataclasses import dataclass, replace

from opspec.model.activities import BlockActivity, GatewayType
from opspec.model.graph import FlowGraph, attached_to, levels
from opspec.model.instance_starts import instance_starts
from opspec.model.process import WorkflowProcess
from opspec.model.soundness_conformance import conformance_violations
from opspec.model.soundness_net import Marking, TokenNet

__all__ = ["KINDS", "TOKEN_BOUND", "Problem", "SoundnessReport", "check_level", "check_process"]

KINDS = ("deadlock", "improper-completion", "livelock", "dead", "and-join-never-fires",
         "unbounded", "conformance", "zero-time-cycle")
TOKEN_BOUND = 4          # more tokens than this on one place: unbounded


@dataclass(frozen=True, slots=True)
class Problem:
    """One soundness problem: ``kind`` is one of :data:`KINDS`; ``witness`` the activities
    fired from the start (or the cycle / the split and what breaks its block, for
    conformance; empty for dead activities). ``severity`` is ``"error"``, or
    ``"warning"`` for what may be intended (a zero-time cycle whose conditions let it out)."""

    kind: str
    process: str
    activity: str | None
    message: str
    witness: tuple[str, ...] = ()
    line: int | None = None
    severity: str = "error"


@dataclass(frozen=True, slots=True)
class SoundnessReport:
    """The verdict on one process level (``process`` is ``"proc"`` or ``"proc/activity-set"``):
    ``states`` markings explored; ``complete`` False when the budget stopped it: then
    ``stopped`` says which (``"states"``: ``max_states`` markings; ``"memory"``: the machine
    ran out of memory first), and the verdict is inconclusive."""

    process: str
    states: int
    complete: bool
    problems: tuple[Problem, ...]
    stopped: str | None = None

    @property
    def sound(self) -> bool:
        """Completely explored and no error (warnings do not make a level unsound)."""
        return self.complete and not any(p.severity == "error" for p in self.problems)


State = tuple[Marking, bool]          # the marking, and whether an end has been reached


def _line(graph: FlowGraph, activity: str | None) -> int | None:
    if activity is None or activity not in graph.by_id:
        return None
    location = graph.by_id[activity].location
    return location.line if location is not None else None


def check_level(process: str, graph: FlowGraph, starts: tuple[str, ...], *,
                max_states: int = 100_000,
                instances: tuple[tuple[str, ...], ...] | None = None) -> SoundnessReport:
    """Explore one level from ``starts`` and report its problems (conformance aside).

    ``instances`` are the start sets of the kinds of instance the engine makes of the level
    (:func:`opspec.model.instance_starts.instance_starts`), each a subset of ``starts``,
    explored together as one space with a root each; default: one, starting at all of
    ``starts``. A start in none of them never runs: it is reported dead.

    Memory is bounded by ``max_states``: at most that many states are kept (a state is its
    marked places and token counts packed in bytes, its parent, the activity fired to reach
    it and, while the exploration can still be complete, the numbers of its successors),
    besides the net of the level itself; see docs/soundness.md for the figures. Should the
    machine run out of memory first, the level is reported inconclusive
    (``stopped="memory"``) rather than raising."""
    try:
        return _explore(process, graph, starts, max_states, instances or (starts,))
    except MemoryError:
        # the states explored so far are gone with the frame; say so instead of crashing
        return SoundnessReport(process, 0, False, (), stopped="memory")


def _pack(marking: Marking, ended: bool) -> bytes:
    """A state as compact bytes: the end flag, then (place, tokens) pairs."""
    flat = array("I", (1 if ended else 0,))
    for place, count in marking:
        flat.append(place)
        flat.append(count)
    return flat.tobytes()


def _unpack(key: bytes) -> State:
    flat = array("I")
    flat.frombytes(key)
    return tuple(zip(flat[1::2], flat[2::2], strict=True)), bool(flat[0])


class _Space:
    """The explored states, numbered in breadth-first order (which is also the order they
    are expanded in): ``keys[n]`` the packed state, ``parent[n]`` and ``via[n]`` (the
    activity fired from the parent, an index into ``names``), and the successors of the
    expanded states as ``targets[offsets[n]:offsets[n + 1]]``."""

    def __init__(self, first: bytes, names: list[str]) -> None:
        self.keys: list[bytes] = [first]
        self.index: dict[bytes, int] = {first: 0}
        self.parent = array("i", (-1,))
        self.via = array("i", (-1,))
        self.names = names
        self.offsets = array("I", (0,))
        self.targets = array("I")
        self.edges = True             # dropped once the exploration cannot be complete

    def add_root(self, key: bytes) -> None:
        """Another initial state (another kind of instance), before the exploration."""
        self.index.setdefault(key, len(self.keys))
        if self.index[key] == len(self.keys):
            self.keys.append(key)
            self.parent.append(-1)
            self.via.append(-1)

    def witness(self, state: int) -> tuple[str, ...]:
        path: list[str] = []
        while self.parent[state] >= 0:
            path.append(self.names[self.via[state]])
            state = self.parent[state]
        return tuple(reversed(path))

    def successors(self, state: int) -> array[int]:
        return self.targets[self.offsets[state]:self.offsets[state + 1]]


def _explore(process: str, graph: FlowGraph, starts: tuple[str, ...],
             max_states: int, instances: tuple[tuple[str, ...], ...]) -> SoundnessReport:
    """The exploration: its memory is bounded by ``max_states`` states (see check_level)."""
    net = TokenNet(graph, starts)
    names = list(graph.by_id)
    number = {name: n for n, name in enumerate(names)}
    roots = list(dict.fromkeys(net.initial(only) for only in instances))
    space = _Space(_pack(roots[0], False), names)
    for root in roots[1:]:            # each kind of instance is a root of its own
        space.add_root(_pack(root, False))
    fired: set[str] = set()
    marked: set[int] = {p for root in roots for p, _ in root}     # places ever marked
    problems: list[Problem] = []
    complete = True
    unbounded = False
    stuck_states: list[int] = []
    cursor = 0
    while cursor < len(space.keys):
        state = cursor
        cursor += 1
        marking, ended = _unpack(space.keys[state])
        moves = list(net.firings(marking))
        if not moves and net.has_tokens(marking):
            stuck_states.append(state)
        for activity_id, after, finished in moves:
            fired.add(activity_id)
            marked.update(p for p, _ in after)
            over = next((p for p, c in net.token_places(after) if c > TOKEN_BOUND), None)
            if over is not None:
                unbounded = True
                target = net.place_target.get(over)
                problems.append(Problem(
                    "unbounded", process, target,
                    f"unbounded: tokens pile up on {net.places[over]!r} before {target!r} "
                    f"(more than {TOKEN_BOUND}): the flow creates tokens faster than it "
                    "consumes them", (*space.witness(state), activity_id),
                    _line(graph, target)))
                break             # one is enough: the rest of the space is unbounded too
            key = _pack(after, ended or finished)
            nxt = space.index.get(key)
            if nxt is None:
                if len(space.keys) >= max_states:
                    if complete:      # no livelock verdict now: the edges are not needed
                        complete = False
                        space.edges = False
                        space.targets = array("I")
                        space.offsets = array("I")
                    continue
                nxt = len(space.keys)
                space.keys.append(key)
                space.index[key] = nxt
                space.parent.append(state)
                space.via.append(number[activity_id])
            if space.edges:
                space.targets.append(nxt)
        if unbounded:
            break
        if space.edges:
            space.offsets.append(len(space.targets))
    problems.extend(_stuck(process, graph, net, space, stuck_states))
    if complete and not unbounded:
        problems.extend(_livelock(process, graph, net, space, stuck_states))
        problems.extend(_dead(process, graph, net, fired, marked, instances))
    return SoundnessReport(process, len(space.keys), complete, tuple(problems),
                           stopped=None if complete else "states")


def _stuck(process: str, graph: FlowGraph, net: TokenNet, space: _Space,
           states: list[int]) -> list[Problem]:
    """Deadlocks and improper completions, one per set of waiting activities (the first
    found, so the one with the shortest witness)."""
    out: list[Problem] = []
    seen: set[tuple[bool, tuple[str, ...]]] = set()
    for state in states:
        marking, ended = _unpack(space.keys[state])
        waiting = net.holders(marking)
        if (ended, tuple(waiting)) in seen:
            continue
        seen.add((ended, tuple(waiting)))
        where = waiting[0] if waiting else None
        if ended:
            message = ("improper completion: an end was reached, but tokens are left behind, "
                       f"waiting at {', '.join(waiting)}")
        else:
            message = f"deadlock: nothing can fire, tokens wait at {', '.join(waiting)}"
        out.append(Problem("improper-completion" if ended else "deadlock", process, where,
                           message, space.witness(state), _line(graph, where)))
    return out


def _livelock(process: str, graph: FlowGraph, net: TokenNet, space: _Space,
              stuck: list[int]) -> list[Problem]:
    """States that can reach neither completion nor a stuck state: the first (shortest)."""
    count = len(space.keys)
    settled = bytearray(count)
    stack = [n for n in range(count) if not net.has_tokens(_unpack(space.keys[n])[0])]
    stack.extend(stuck)
    for n in stack:
        settled[n] = 1
    # the edges backwards, as arrays (counting sort by target)
    starts = array("I", bytes(4 * (count + 1)))
    for target in space.targets:
        starts[target + 1] += 1
    for n in range(count):
        starts[n + 1] += starts[n]
    sources = array("I", bytes(4 * len(space.targets)))
    fill = array("I", starts)
    for source in range(count):
        for target in space.successors(source):
            sources[fill[target]] = source
            fill[target] += 1
    del fill
    while stack:
        node = stack.pop()
        for source in sources[starts[node]:starts[node + 1]]:
            if not settled[source]:
                settled[source] = 1
                stack.append(source)
    state = next((n for n in range(count) if not settled[n]), None)   # BFS order: shortest
    if state is None:
        return []
    # every successor of a lost state is lost too: walk on until a state repeats, so the
    # witness shows the loop the tokens are caught in
    walk: list[str] = []
    loop: list[str] = []
    seen = {state: 0}
    path = [state]
    node = state
    while len(space.successors(node)):
        nxt = space.successors(node)[0]
        walk.append(_fired_between(net, space.keys[node], space.keys[nxt]))
        if nxt in seen:
            loop = walk[seen[nxt]:]
            break
        seen[nxt] = len(walk)
        path.append(nxt)
        node = nxt
    # placed where the tokens enter the loop (the first state of the walk that holds one at
    # an activity of the loop), not at the first lost state, which is often the start event
    # of a process lost from its start
    in_loop = set(loop)
    entered = next((n for n in path
                    if in_loop.intersection(net.holders(_unpack(space.keys[n])[0]))), state)
    holders = net.holders(_unpack(space.keys[entered])[0])
    active = [a for a in holders if a in in_loop] or holders
    where = active[0] if active else None
    if where in in_loop:        # the loop's activities named from where it is entered
        turn = loop.index(where)
        loop = loop[turn:] + loop[:turn]
    names = ", ".join(dict.fromkeys(loop)) or ", ".join(active)
    return [Problem(
        "livelock", process, where,
        "livelock: once here the process can never complete, it loops for ever through "
        f"{names} (give the loop a way out)", (*space.witness(state), *walk),
        _line(graph, where))]


def _fired_between(net: TokenNet, before: bytes, after: bytes) -> str:
    """The activity whose firing turns ``before`` into ``after``."""
    marking, ended = _unpack(before)
    return next(activity for activity, result, finished in net.firings(marking)
                if _pack(result, ended or finished) == after)


def _dead(process: str, graph: FlowGraph, net: TokenNet, fired: set[str],
          marked: set[int], instances: tuple[tuple[str, ...], ...]) -> list[Problem]:
    out: list[Problem] = []
    started = {s for only in instances for s in only}
    unstarted = [s for s in net.start_place if s not in started]
    for activity in graph.by_id.values():
        if activity.id in fired or attached_to(activity) is not None:
            continue     # a boundary event not interrupting anything is not dead code
        inputs = net.inputs[activity.id]
        if net.join[activity.id] is GatewayType.COMPLEX:
            never = [net.places[p] for p in inputs if p not in marked]
            why = (f"{', '.join(never)} never get(s) a token" if never else
                   "its IncomingCondition never holds for the tokens that arrive together")
            out.append(Problem(
                "dead", process, activity.id,
                f"complex join {activity.id!r} can never fire: of its incoming transitions, "
                f"{why}", (), _line(graph, activity.id)))
        elif net.join[activity.id] is GatewayType.AND and len(inputs) > 1:
            never = [net.places[p] for p in inputs if p not in marked]
            why = (f"{', '.join(never)} never get(s) a token" if never else
                   "each gets tokens, but never all at the same time")
            out.append(Problem(
                "and-join-never-fires", process, activity.id,
                f"AND-join {activity.id!r} can never fire: of its incoming transitions, {why}",
                (), _line(graph, activity.id)))
        elif activity.id in unstarted:
            begins = " or ".join(", ".join(repr(s) for s in only) for only in instances)
            out.append(Problem(
                "dead", process, activity.id,
                f"dead activity: {activity.id!r} can never run: no transition leads to it, "
                f"and no instance starts there (an instance begins at {begins}: a start "
                "event with a trigger starts an instance that runs only its path); add a "
                "transition to it, or remove it", (), _line(graph, activity.id)))
        else:
            out.append(Problem("dead", process, activity.id,
                               f"dead activity: {activity.id!r} can never run", (),
                               _line(graph, activity.id)))
    return out


def _block_starts(process: WorkflowProcess) -> dict[str, str | None]:
    """The StartActivityId each activity set is started at (the first BlockActivity's)."""
    starts: dict[str, str | None] = {}
    activities = [*process.activities, *(a for s in process.activity_sets for a in s.activities)]
    for activity in activities:
        body = activity.body
        if isinstance(body, BlockActivity):
            starts.setdefault(body.activity_set, body.start_activity)
    return starts


def check_process(process: WorkflowProcess, *, conformance: str | None = None,
                  max_states: int = 100_000, called: bool = False) -> list[SoundnessReport]:
    """A report per level of ``process`` (the process, then each activity set), each explored
    up to ``max_states`` markings; ``conformance`` is the package's GraphConformance;
    ``called``: a SubFlow of the package calls the process (its instances then start as a
    call starts them, :func:`opspec.model.instance_starts.instance_starts`)."""
    reports = []
    block_starts = _block_starts(process)
    for activity_set, graph in levels(process):
        instances = None
        if activity_set is None:
            name, starts = process.id, graph.starts()
            instances = instance_starts(process, graph, called=called)
        else:
            name = f"{process.id}/{activity_set.id}"
            starts = graph.starts(block_starts.get(activity_set.id))
        report = check_level(name, graph, starts, max_states=max_states, instances=instances)
        extra = tuple(Problem("conformance", name, activity, message, witness,
                              _line(graph, activity))
                      for activity, message, witness in
                      conformance_violations(graph, conformance or ""))
        if extra:
            report = replace(report, problems=report.problems + extra)
        reports.append(report)
    return reports
