"""Joins that wait: AND and StartQuantity joins count in :meth:`Flow._arrive`; here are the
ones that decide later — complex joins (an activation condition, then a reset) and OR joins,
which fire once nothing elsewhere in the frame can still bring them a token (BPMN 2.0 Table
13.3) — and the check, when the ready queue runs dry, for frames left with only parked tokens
(a deadlock). The rules are in docs/semantics.md."""

from __future__ import annotations

from collections import ChainMap
from typing import TYPE_CHECKING

from opspec.engine.compiled import CompiledActivity
from opspec.engine.instances import Frame, ProcessInstance
from opspec.engine.lifecycle import ABORTED, RUNNING
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError

if TYPE_CHECKING:
    from opspec.engine.flow import Flow

__all__ = ["complex_arrival", "complex_fires", "or_ready", "report_deadlock", "resolve_frames"]


def complex_arrival(flow: Flow, frame: Frame, act: CompiledActivity, slot: int) -> bool:
    """A token (already counted as parked) reaches complex join ``act`` on ``slot``;
    whether the join fires now (BPMN 2.0 §13.4.4: fire when the activation condition
    holds, consuming a token of each incoming transition that has one; then ignore one
    token on each of the others before firing again)."""
    index = act.index
    if frame.cjoins is None:
        frame.cjoins = {}
        frame.owed = {}
    assert frame.owed is not None
    counts = frame.cjoins.get(index)
    if counts is None:
        counts = frame.cjoins[index] = [0] * len(act.in_slots)
    owed = frame.owed.get(index)
    if owed is not None and slot in owed:       # waiting for reset: this one is ignored
        owed.discard(slot)
        frame.parked -= 1
        if owed:
            return False
        del frame.owed[index]
        return complex_fires(flow, frame, act, counts) if any(counts) else False
    counts[slot] += 1
    if owed is not None:
        return False
    return complex_fires(flow, frame, act, counts)


def complex_fires(flow: Flow, frame: Frame, act: CompiledActivity, counts: list[int]) -> bool:
    inst = frame.inst
    active = sum(1 for c in counts if c)
    condition = act.join_condition
    assert condition is not None
    try:
        holds = condition(ChainMap({"activationCount": active}, inst.scope), flow.state.now)
    except OpspecError as error:
        flow.abort(inst, act, f"the IncomingCondition failed: {error.message}")
        return False
    if not holds:
        return False
    owed = set()
    for slot, count in enumerate(counts):
        if count:
            counts[slot] -= 1
            frame.parked -= 1
        else:
            owed.add(slot)
    if owed and frame.owed is not None:
        frame.owed[act.index] = owed
    return True


def resolve_frames(flow: Flow) -> None:
    """OR joins that nothing can reach any more fire; a frame with only parked tokens
    left is deadlocked (an AND join that cannot fire)."""
    frames = list(flow.state.pending)
    flow.state.pending.clear()
    for frame in frames:
        if frame.inst.state != RUNNING:
            continue
        fired = False
        ors = frame.ors if frame.ors is not None else {}
        for join, tokens in list(ors.items()):
            if or_ready(frame, join, tokens):
                # one activation consumes one token of each incoming transition that
                # has one (BPMN 2.0 Table 13.3); tokens left over wait for the next
                for slot, count in enumerate(tokens):
                    if count:
                        tokens[slot] = count - 1
                        frame.parked -= 1
                if not any(tokens):
                    del ors[join]
                else:
                    flow.state.pending[frame] = None
                frame.live += 1
                fired = True
                flow.state.ready.append((flow.start_at_q, frame, join, None))
        if frame.owed and frame.live <= 0 and not fired:     # (only complex joins)
            # nothing can deliver the tokens a fired complex join waits for: it resets,
            # and the tokens that came meanwhile may fire it again at once
            frame.owed.clear()
            acts = frame.graph.activities
            for join, counts in list((frame.cjoins or {}).items()):
                if any(counts) and complex_fires(flow, frame, acts[join], counts):
                    frame.live += 1
                    fired = True
                    flow.state.ready.append((flow.start_at_q, frame, join, None))
        if not fired and frame.live <= 0:
            if frame.parked:
                waiting = [frame.graph.activities[i].id
                           for i, c in (list((frame.joins or {}).items())
                                        + list((frame.ors or {}).items())
                                        + list((frame.cjoins or {}).items()))
                           if (c if isinstance(c, int) else any(c))]
                report_deadlock(flow, frame.inst, waiting, "a join waits for branches "
                                     "that can no longer arrive")
            else:
                flow.frame_done(frame)


def or_ready(frame: Frame, join: int, tokens: list[int]) -> bool:
    """Whether OR join ``join`` is activated (BPMN 2.0 Table 13.3): some incoming
    transition has a token, and every token elsewhere in the frame that can reach an
    incoming transition without one (not passing through the join) can also reach one
    that has a token."""
    if not any(tokens):
        return False
    reach = frame.graph.activities[join].or_reach
    for ai in frame.running.values():
        if _or_blocks(reach, tokens, ai.act.index):
            return False
    for other, waiting in (frame.ors or {}).items():
        if other != join and any(waiting) and _or_blocks(reach, tokens, other):
            return False
    for other, counts in (frame.joins or {}).items():
        if any(counts) and _or_blocks(reach, tokens, other):
            return False
    if frame.cjoins:
        for other, counts in frame.cjoins.items():
            if any(counts) and _or_blocks(reach, tokens, other):
                return False
    return True


def _or_blocks(reach: tuple[frozenset[int], ...], tokens: list[int], node: int) -> bool:
    """A token at ``node`` holds an OR join back when it can reach an incoming transition
    that has no token and none that has one."""
    blocked = False
    for slot, nodes in enumerate(reach):
        if node in nodes:
            if tokens[slot]:
                return False
            blocked = True
    return blocked


def report_deadlock(flow: Flow, inst: ProcessInstance, waiting: list[str], why: str) -> None:
    """Record a deadlock of ``inst`` (trace + summary) and abort it."""
    state = flow.state
    proc = inst.process
    text = (f"deadlock in process {proc.id!r} (instance {inst.id}) at "
            f"t={state.now:.3f} s: {why}; waiting: {', '.join(waiting) or '-'}")
    state.deadlocks.append({"time": state.now, "process": proc.id, "instance": inst.id,
                            "waiting": waiting, "message": text})
    if state.wants(EK.DEADLOCK, proc.id, None):
        state.emit(EK.DEADLOCK, proc.id, inst.id, None, proc.lane, None,
                   {"waiting": list(waiting), "message": text})
    flow.end_instance(inst, ABORTED, text)
