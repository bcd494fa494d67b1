"""Zero-time cycles, found before a run: what ``opspec check`` reports as ``zero-time-cycle``.

A run stops with a :class:`~opspec.errors.ZeroTimeCycleError` when its clock stops advancing
(:mod:`opspec.engine.zero_time`). This finds the cycles that can do that, statically, on the
compiled package (so *instantaneous* means exactly what the engine runs in zero time), and
reports only cycles that certainly take no time:

- every activity of the cycle is *instantaneous* under the dedicated processor model: no
  implementation, a route, a throwing or none event, or an asynchronous subflow start, with no
  duration (or one whose draws are all under :data:`ZENO_SECONDS`: a Zeno cycle), CPU demand, deadline, start/end trigger, boundary event, multi-instance loop or
  AND/OR/complex join (tasks are left out: a callable bound at run time may take time; so are
  manual activities, catching events, timers and synchronous subflows, which wait);
- the cycle is reachable from a start of its level (conditions abstracted: any branch);
- a standard loop on an instantaneous activity is a cycle of that one activity;
- workflows that start each other asynchronously, each through instantaneous activities only
  from its start, spawn instances without end at one instant.

Whether a run actually goes round forever depends on data (a counted loop ends), so each
finding is a warning with its witness: the activities from the start into the cycle, then
once round it. One is certain and so an error: workflows that start each other through no
choice at all (each from its only start, every step on the way unconditional). Such a
package can never finish: van der Aalst's soundness asks that "for any case, the procedure
will terminate eventually" (option to complete), and every instance started leaves a new one
behind at the same instant, so ``check`` calls it not sound.
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Iterable

from opspec.engine.compiled import (
    J_XOR,
    K_ASYNC,
    K_NOOP,
    K_THROW,
    S_AND,
    T_NONE,
    CompiledActivity,
    CompiledGraph,
    CompiledPackage,
)
from opspec.model.soundness import Problem

__all__ = ["KIND", "zero_time_cycles"]

KIND = "zero-time-cycle"


#: A duration every draw of which is shorter than this many seconds is taken as no time: a
#: cycle through it moves the clock by so little per round (1e-17 s in a fuzzed spec) that
#: the run is Zeno, stuck at one instant as surely as a cycle of no time at all.
ZENO_SECONDS = 1e-9
# draws of a duration's sampler looked at (seeded: the same answer every time)
_PROBES = 32


def _negligible(act: CompiledActivity) -> bool:
    """Whether ``act``'s declared duration is no duration: every probe draw is under
    :data:`ZENO_SECONDS` (none declared: trivially)."""
    sampler = act.sampler
    if sampler is None:
        return True
    import numpy as np

    rng = np.random.default_rng(0)
    try:
        return all(sampler(rng) < ZENO_SECONDS for _ in range(_PROBES))
    except Exception:  # noqa: BLE001 - a sampler that cannot draw: judged at run time
        return False


def _instant_body(act: CompiledActivity) -> bool:
    """Instantaneous apart from a standard loop (which makes it a cycle of its own); a
    duration too short to move the clock (:data:`ZENO_SECONDS`) counts as none."""
    return (act.kind in (K_NOOP, K_THROW, K_ASYNC) and not act.deadlines and act.mi is None
            and _negligible(act) and act.cpu == 0.0 and act.start_trigger is None
            and act.end_trigger is None and not act.boundary and act.attached_to < 0
            and not act.choice and not act.terminate and act.coordination is None
            and (act.join == J_XOR or len(act.in_slots) <= 1))


def _successors(act: CompiledActivity) -> list[int]:
    return list(dict.fromkeys(t.target for t in (*act.out, *act.otherwise)))


def _unconditional(act: CompiledActivity) -> bool:
    """Whether every token leaving ``act`` takes each of its transitions: no condition, no
    drawn branch, no default, and one transition or an AND split."""
    return (not act.otherwise and bool(act.out) and (len(act.out) == 1 or act.split == S_AND)
            and all(t.kind == T_NONE and t.condition is None and t.probability < 0
                    and t.exception is None for t in act.out))


def _certain(graph: CompiledGraph, path: list[int]) -> bool:
    """Whether every run of the graph goes along ``path`` (from its only start)."""
    return (len(graph.starts) == 1 and path[0] == graph.starts[0]
            and all(_unconditional(graph.activities[i]) for i in path[:-1]))


def _line(act: CompiledActivity) -> int | None:
    return act.location.line if act.location is not None else None


def _paths(graph: CompiledGraph, sources: Iterable[int]) -> dict[int, int | None]:
    """Breadth-first parents of every activity reachable from ``sources`` (any branch)."""
    parents: dict[int, int | None] = {s: None for s in sources}
    queue = deque(parents)
    while queue:
        at = queue.popleft()
        for nxt in (*_successors(graph.activities[at]), *graph.activities[at].boundary):
            if nxt not in parents:
                parents[nxt] = at
                queue.append(nxt)
    return parents


def _path_to(parents: dict[int, int | None], target: int) -> list[int]:
    path = [target]
    link = parents[target]
    while link is not None:
        path.append(link)
        link = parents[link]
    return path[::-1]


def _components(nodes: list[int], edges: dict[int, list[int]]) -> list[list[int]]:
    """Strongly connected components (Tarjan, iterative), in discovery order."""
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    stack: list[int] = []
    on: set[int] = set()
    out: list[list[int]] = []
    counter = 0
    for root in nodes:
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            node, i = work.pop()
            if i == 0:
                index[node] = low[node] = counter
                counter += 1
                stack.append(node)
                on.add(node)
            succ = edges.get(node, [])
            if i < len(succ):
                work.append((node, i + 1))
                nxt = succ[i]
                if nxt not in index:
                    work.append((nxt, 0))
                elif nxt in on:
                    low[node] = min(low[node], index[nxt])
                continue
            if low[node] == index[node]:
                comp = []
                while True:
                    member = stack.pop()
                    on.discard(member)
                    comp.append(member)
                    if member == node:
                        break
                out.append(comp)
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
    return out


def _round(edges: dict[int, list[int]], members: set[int], entry: int) -> list[int]:
    """A shortest way from ``entry`` back to itself inside ``members``."""
    parents: dict[int, int] = {}
    queue = deque([entry])
    while queue:
        at = queue.popleft()
        for nxt in edges.get(at, []):
            if nxt not in members:
                continue
            if nxt == entry:
                path = [entry]
                while at != entry:
                    path.append(at)
                    at = parents[at]
                path.append(entry)
                return path[::-1]
            if nxt not in parents:
                parents[nxt] = at
                queue.append(nxt)
    return [entry, entry]


def _graphs(graph: CompiledGraph, name: str) -> Iterable[tuple[str, CompiledGraph]]:
    yield name, graph
    for act in graph.activities:
        if act.block is not None:
            yield from _graphs(act.block, f"{name}/{act.block.name}")


def _level(name: str, graph: CompiledGraph) -> list[Problem]:
    acts = graph.activities
    reach = _paths(graph, graph.starts)
    instant = {a.index for a in acts if a.index in reach and _instant_body(a)}
    edges = {i: [j for j in _successors(acts[i]) if j in instant] for i in instant}
    for i in instant:
        if acts[i].loop is not None:
            edges[i].append(i)
    problems = []
    depth: dict[int, int] = {}      # BFS depth (the parents are in BFS order): no path walks
    for node, parent in reach.items():
        depth[node] = 0 if parent is None else depth[parent] + 1
    for comp in _components(sorted(instant, key=lambda i: (depth[i], i)), edges):
        members = set(comp)
        if len(comp) == 1 and comp[0] not in edges[comp[0]]:
            continue
        entry = min(members, key=lambda i: (depth[i], i))
        cycle = _round(edges, members, entry)
        into = _path_to(reach, entry)
        exits = any(j not in members for i in members for j in _successors(acts[i]))
        ids = [acts[i].id for i in cycle]
        loop = len(comp) == 1 and acts[entry].loop is not None and len(cycle) == 2
        others = [acts[i].id for i in sorted(members - set(cycle))]
        also = f" (and through {', '.join(others)})" if others else ""
        what = (f"activity {acts[entry].id!r} loops with a body that takes no time" if loop
                else f"zero-time cycle {' -> '.join(ids)}{also}: every activity in it is "
                     "instantaneous")
        way_out = ("and it has no way out, so a run that gets there never leaves that "
                   "instant" if not exits and not loop else
                   "if its conditions never let the token out, the clock stops there")
        problems.append(Problem(
            KIND, name, acts[entry].id,
            f"{what}; {way_out} (a run then stops with a zero-time cycle error)",
            tuple(acts[i].id for i in into) + tuple(ids[1:]), _line(acts[entry]),
            severity="warning"))
    return problems


def _spawns(compiled: CompiledPackage) -> list[Problem]:
    """Workflows that start each other asynchronously, instantaneously from their starts."""
    calls: dict[str, dict[str, list[str]]] = {}       # process -> callee -> witness
    certain: set[tuple[str, str]] = set()               # (caller, callee) on every run
    for pid, proc in compiled.processes.items():
        graph = proc.graph
        parents: dict[int, int | None] = {s: None for s in graph.starts
                                          if _instant_body(graph.activities[s])}
        queue = deque(parents)
        while queue:
            at = queue.popleft()
            act = graph.activities[at]
            if act.kind == K_ASYNC and act.subflow in compiled.processes:
                path = _path_to(parents, at)
                calls.setdefault(pid, {}).setdefault(
                    act.subflow, [graph.activities[i].id for i in path])
                if _certain(graph, path):
                    certain.add((pid, act.subflow))
            for nxt in _successors(act):
                if nxt not in parents and _instant_body(graph.activities[nxt]):
                    parents[nxt] = at
                    queue.append(nxt)
    names = sorted(calls)
    number = {n: i for i, n in enumerate(sorted(compiled.processes))}
    edges = {number[p]: [number[c] for c in calls[p]] for p in names}
    back = {i: n for n, i in number.items()}
    problems = []
    for comp in _components([number[p] for p in names], edges):
        if len(comp) == 1 and comp[0] not in edges.get(comp[0], []):
            continue
        members = set(comp)
        entry = min(members)
        ring = [back[i] for i in _round(edges, members, entry)]
        witness: list[str] = []
        for caller, callee in itertools.pairwise(ring):
            witness.extend(f"{caller}:{a}" for a in calls[caller][callee])
        witness.append(witness[0])                  # and round again
        first = compiled.processes[ring[0]]
        act = first.graph.activities[first.graph.by_id[calls[ring[0]][ring[1]][-1]]]
        # the ring found is one of possibly several in the component: it is certain when
        # each of its starts is
        sure = all(pair in certain for pair in itertools.pairwise(ring))
        problems.append(Problem(
            KIND, ring[0], act.id,
            f"workflows start each other asynchronously with no delay: "
            f"{' -> '.join(ring)}; each start is instantaneous, so once one runs, "
            "instances are spawned without end at one instant (a run then stops with a "
            "zero-time cycle error)" + (
                "; no condition on the way stops it, so the workflow can never complete "
                "(not sound: option to complete; put a delay or a condition before the "
                "start)" if sure else ""),
            tuple(witness), _line(act), severity="error" if sure else "warning"))
    return problems


def zero_time_cycles(compiled: CompiledPackage,
                     processes: Iterable[str] | None = None) -> list[Problem]:
    """The zero-time cycles of ``processes`` (default: every process): warnings, and errors
    for the workflows certain to start each other without end (see the module docstring)."""
    wanted = set(compiled.processes if processes is None else processes)
    problems: list[Problem] = []
    for pid in sorted(wanted & set(compiled.processes)):
        for name, graph in _graphs(compiled.processes[pid].graph, pid):
            problems.extend(_level(name, graph))
    problems.extend(p for p in _spawns(compiled) if p.process in wanted)
    return problems
