"""The coordination built-ins at run time: an arbiter, voter or superposition computed, data
pushed to or pulled from a supervisor mailbox, a mode changed (what each does:
:mod:`opspec.engine.coordination`).

Most of them start and complete at once. :func:`at_once` runs such an activity without an
:class:`~opspec.engine.instances.ActivityInstance` (the same trace, data and next activity as
through one; a robot's periodic workflows run an arbiter, a push or a pull most periods);
:func:`coordinate` is the body of one that has an instance (:meth:`Activities._body`)."""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any, Final

from opspec.engine import coordination as coord
from opspec.engine.compiled import CompiledActivity
from opspec.engine.instances import ActivityInstance, Frame
from opspec.engine.lifecycle import RUNNING, SUSPENDED
from opspec.engine.trace import EventKind as EK
from opspec.model import CoordinationKind

if TYPE_CHECKING:
    from opspec.engine.activities import Activities

# Compiled, an enum member read from its class goes through the metaclass (2.5k per robot instance)
_ARBITER: Final = CoordinationKind.ARBITER
_VOTER: Final = CoordinationKind.VOTER
_SUPERPOSITION: Final = CoordinationKind.SUPERPOSITION
_PUSH_DATA: Final = CoordinationKind.PUSH_DATA
_PULL_DATA: Final = CoordinationKind.PULL_DATA

#: what :func:`at_once` returns when it did nothing: the caller starts an instance
_NOT_NOW: Final = False


def at_once(acts: Activities, frame: Frame, act: CompiledActivity) -> bool:
    """Start and complete ``act``, a coordination built-in that
    :meth:`Activities.start_slow` would run at once through an instance, without one: what
    ``start_slow``, :func:`coordinate`, ``body_done`` and ``_complete`` do, in that order.
    ``False`` (nothing done) where the instance is needed or might be seen: a mode change
    (it stops the activities running), start assignments, an instance suspended, data
    rules (a data change runs them while the activity would be running), an input missing
    or a computation failing (the activity fails), a pull finding its mailbox empty (it
    waits)."""
    state = acts.state
    inst = frame.inst
    spec = act.coordination
    if (spec is None or act.start_assign or state.rules or inst.state == SUSPENDED
            or act.general and state.pooled):
        return _NOT_NOW
    kind = spec.kind
    scope = inst.scope                      # ActivityInstance.scope without its locals
    values: list[Any] = []
    try:
        for name in spec.inputs:
            values.append(scope[name])
    except KeyError:
        return _NOT_NOW
    result: Any = None
    box: deque[Any] | None = None
    if kind is _ARBITER:
        result = first_set(values)
    elif kind is _VOTER or kind is _SUPERPOSITION:
        try:
            result = (coord.voter(values, spec.options) if kind is _VOTER
                      else coord.superposition(values, spec.weights))
        except (TypeError, ValueError):
            return _NOT_NOW
    elif kind is _PULL_DATA:
        box = state.mailboxes.get(spec.channel or act.id)
        if not box:
            return _NOT_NOW
    elif kind is not _PUSH_DATA:
        return _NOT_NOW
    state.last_key += 1                     # the key the instance would have taken
    cached = act.flag_cache                 # RunState.act_bits's cached case, in line
    if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 1:
        state.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                   act.participant)
    output = spec.output
    if kind is _PUSH_DATA:
        push(acts, spec.channel or act.id, values[0] if len(values) == 1 else tuple(values))
    elif box is not None and output:      # (without an output the value stays, as there)
        result = box.popleft()
    if output and kind is not _PUSH_DATA:
        acts.flow.set_field(inst, act, output, result)
    # Activities._complete, the instance's part left out
    if act.simple_end:
        cached = act.flag_cache
        if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 2:
            state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                       act.participant)
        nxt = act.next
        target = frame.graph.activities[nxt] if nxt >= 0 else None
        if target is None or target.join:
            target = acts.flow.split(frame, act, inst)
    else:
        target = acts.flow.done_next(frame, act)
    if target is not None:
        if target.fast:
            acts.start(frame, target)
        else:
            acts.start_slow(frame, target)
    return True


def first_set(commands: list[Any]) -> Any:
    """:func:`coordination.arbiter`, compiled (that module is not: a call into it through
    Python's protocol is 1.2k instructions, once a period on a robot)."""
    for command in commands:
        if command is not None and command != "":
            return command
    return None


def coordinate(acts: Activities, ai: ActivityInstance) -> None:
    """The body of a coordination built-in run as an instance: done (``body_done``), or
    waiting for a push (a pull from an empty mailbox), or failed."""
    act = ai.act
    spec = act.coordination
    assert spec is not None
    scope = ai.scope()
    try:
        values = [scope[name] for name in spec.inputs]
    except KeyError as error:
        acts.fail(ai, "coordination", f"data field {error.args[0]!r} does not exist")
        return
    kind = spec.kind
    try:
        if kind is _ARBITER:
            result: Any = first_set(values)
        elif kind is _VOTER:
            result = coord.voter(values, spec.options)
        elif kind is _SUPERPOSITION:
            result = coord.superposition(values, spec.weights)
        elif kind is _PUSH_DATA:
            push(acts, spec.channel or act.id, values[0] if len(values) == 1
                 else tuple(values))
            acts.body_done(ai, None)
            return
        elif kind is _PULL_DATA:
            channel = spec.channel or act.id
            box = acts.state.mailboxes.get(channel)
            if box:
                acts.body_done(ai, {spec.output: box.popleft()} if spec.output else None)
            else:
                ai.waiting = f"pull from mailbox {channel!r}"
                acts.state.pullers.setdefault(channel, deque()).append(ai)
            return
        else:
            # at once: a mode ending this instance stops all after it (its completion too)
            acts.triggers.change_mode(spec.target_mode or "", act, ai.frame.inst)
            acts.body_done(ai, None)
            return
    except (TypeError, ValueError) as error:
        acts.fail(ai, "coordination", f"{kind.value} failed: {error}")
        return
    acts.body_done(ai, {spec.output: result} if spec.output else None)


def push(acts: Activities, channel: str, value: Any) -> None:
    """Put ``value`` into supervisor mailbox ``channel``; a waiting pull gets it."""
    state = acts.state
    pullers = state.pullers.get(channel)
    while pullers:
        ai = pullers.popleft()
        if ai.state == RUNNING:
            output = ai.act.coordination.output if ai.act.coordination else None
            state.ready.append((acts.body_done_q, ai, {output: value} if output else None,
                                None))
            return
    state.mailboxes.setdefault(channel, deque()).append(value)
