"""XPDL graph conformance classes, checked on one process level.

``NON_BLOCKED`` (the default) restricts nothing. ``LOOP_BLOCKED``: the transitions of a level
form no cycle (repetition goes into an activity's Loop, a BlockActivity or a subflow, whose
insides are levels of their own). ``FULL_BLOCKED`` additionally wants the graph built of
blocks: every split is closed by a join of the same kind (XOR or event-based by XOR, AND by AND,
OR by OR) and the region between them has one entry (the split) and one exit (the join).

The join closing a split is its *immediate post-dominator* (the first activity every path
from the split to an end passes through); exception transitions and boundary events are not
part of the blocks. Violations come as ``(activity, message, witness)``: the cycle, or the
split and what breaks its block.
"""

from __future__ import annotations

from opspec.model.activities import GatewayType
from opspec.model.graph import EXCEPTION_KINDS, FlowGraph
from opspec.model.soundness_net import join_type, split_type

__all__ = ["CLASSES", "Violation", "conformance_violations"]

CLASSES = ("NON_BLOCKED", "LOOP_BLOCKED", "FULL_BLOCKED")

Violation = tuple[str, str, tuple[str, ...]]     # (activity, message, witness)

_EXIT = "\0exit"           # virtual node after every end, so that post-dominators exist


def _normal_successors(graph: FlowGraph) -> dict[str, list[str]]:
    return {a: list(dict.fromkeys(t.target for t in graph.outgoing[a]
                                  if t.condition.kind not in EXCEPTION_KINDS))
            for a in graph.by_id}


def _post_dominators(succ: dict[str, list[str]]) -> dict[str, set[str]]:
    """Iterative data flow: pdom(n) = {n} ∪ ⋂ pdom(s) over the successors s of n."""
    nodes = [*succ, _EXIT]
    everything = set(nodes)
    pdom: dict[str, set[str]] = {n: set(everything) for n in succ}
    pdom[_EXIT] = {_EXIT}
    changed = True
    while changed:
        changed = False
        for node, targets in succ.items():
            outs = targets or [_EXIT]
            new = set.intersection(*(pdom[t] for t in outs)) | {node}
            if new != pdom[node]:
                pdom[node] = new
                changed = True
    return pdom


def _immediate(node: str, pdom: dict[str, set[str]]) -> str | None:
    """The strict post-dominator of ``node`` that every other one post-dominates."""
    strict = pdom[node] - {node}
    for candidate in strict:
        if candidate != _EXIT and strict <= pdom[candidate] | {candidate}:
            return candidate
    return None


def conformance_violations(graph: FlowGraph, klass: str) -> list[Violation]:
    """What keeps ``graph`` from the conformance class ``klass`` (any case; unknown or
    NON_BLOCKED: nothing)."""
    klass = klass.upper()
    out: list[Violation] = []
    if klass not in ("LOOP_BLOCKED", "FULL_BLOCKED"):
        return out
    cycle = graph.find_cycle()
    if cycle is not None:
        out.append((cycle[0], (f"the package declares GraphConformance {klass}, which forbids "
                    f"cycles, but the process has one: {' -> '.join(cycle)} (repeat with a "
                    "Loop on an activity or a BlockActivity, or declare NON_BLOCKED)"), cycle))
    if klass == "FULL_BLOCKED":
        out.extend(_blocks(graph))
    return out


def _blocks(graph: FlowGraph) -> list[Violation]:
    succ = _normal_successors(graph)
    pred: dict[str, list[str]] = {a: [] for a in succ}
    for source, targets in succ.items():
        for target in targets:
            pred[target].append(source)
    pdom = _post_dominators(succ)
    closed: set[str] = set()
    out: list[Violation] = []
    for split_id, targets in succ.items():
        if len(targets) < 2:
            continue
        kind = split_type(graph.by_id[split_id])
        want = GatewayType.XOR if kind in (GatewayType.EVENT, GatewayType.COMPLEX) else kind
        join_id = _immediate(split_id, pdom)
        if join_id is None:
            out.append((split_id, (f"FULL_BLOCKED: the branches of the {kind.value} split "
                        f"{split_id!r} never meet again (close them with a {want.value} join)"),
                        (split_id, *targets)))
            continue
        closed.add(join_id)
        join = graph.by_id[join_id]
        if len(pred[join_id]) < 2 or join_type(join) is not want:
            found = (f"a {join_type(join).value} join" if len(pred[join_id]) > 1
                     else "an activity that is no join")
            out.append((split_id, (f"FULL_BLOCKED: the {kind.value} split {split_id!r} is "
                        f"closed at {join_id!r}, {found}; declare <Join Type="
                        f"\"{want.value}\"> there"), (split_id, join_id)))
            continue
        inside = graph.reachable(targets, avoid=[join_id, split_id])
        for node in sorted(inside):
            intruder = next((p for p in pred[node] if p not in inside and p != split_id), None)
            if intruder is not None:
                out.append((split_id, (f"FULL_BLOCKED: the block from {split_id!r} to "
                            f"{join_id!r} is entered from outside, by {intruder!r} -> "
                            f"{node!r} (a block has one entry and one exit)"),
                            (split_id, intruder, node, join_id)))
                break
    for join_id, sources in pred.items():
        if len(sources) > 1 and join_id not in closed:
            out.append((join_id, (f"FULL_BLOCKED: the join {join_id!r} (from "
                        f"{', '.join(repr(s) for s in sources)}) closes no split"),
                        (*sources, join_id)))
    return out
