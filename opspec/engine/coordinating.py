"""The coordination built-ins at run time: an arbiter, voter or superposition computed, data
pushed to or pulled from a supervisor mailbox, a mode changed (what each does:
:mod:`opspec.engine.coordination`).

Most of them start and complete at once. :func:`at_once` runs such an activity without an
:class:`~opspec.engine.instances.ActivityInstance` (the same trace, data and next activity as
through one; a robot's periodic workflows run an arbiter, a push or a pull most periods);
:func:`coordinate` is the body of one that has an instance (:meth:`Activities._body`)."""

from __future__ import annotations

from collections import deque
from collections.abc import MutableMapping
from typing import TYPE_CHECKING, Any, Final, final

from opspec.engine import coordination as coord
from opspec.engine.compiled import CompiledActivity
from opspec.engine.conditions import field_name
from opspec.engine.instances import ActivityInstance, Frame
from opspec.engine.lifecycle import RUNNING, SUSPENDED
from opspec.engine.scope import Scope
from opspec.engine.trace import EventKind as EK
from opspec.model import CoordinationBuiltIn, CoordinationKind

if TYPE_CHECKING:
    from opspec.engine.activities import Activities

# Compiled, an enum member read from its class goes through the metaclass (2.5k per robot instance)
_ARBITER: Final = CoordinationKind.ARBITER
_VOTER: Final = CoordinationKind.VOTER
_SUPERPOSITION: Final = CoordinationKind.SUPERPOSITION
_PUSH_DATA: Final = CoordinationKind.PUSH_DATA
_PULL_DATA: Final = CoordinationKind.PULL_DATA

#: a deque's two methods used here, called as functions: compiled, a method of a class
#: mypyc does not compile is looked up by name at each call (about 90 instructions)
_APPEND: Final = deque.append
_POPLEFT: Final = deque.popleft

#: what :func:`at_once` returns when it did nothing: the caller starts an instance
_NOT_NOW: Final = False

# The kinds as the native integers a :class:`Coord` holds
ARBITER: Final = 0
VOTER: Final = 1
SUPERPOSITION: Final = 2
PUSH: Final = 3
PULL: Final = 4
OTHER: Final = 5                        # a mode change


@final
class Coord:
    """An activity's coordination built-in (``spec``, the model's
    :class:`~opspec.model.CoordinationBuiltIn`) as compiled fields: the model's class is a
    Python dataclass, and compiled code read each of its fields through Python's protocol
    (about five reads a built-in run at once, once a period on a robot). ``channel`` is the
    mailbox (the activity's id without a channel of its own), ``waiting`` what a pull
    waiting on it says."""

    def __init__(self, spec: CoordinationBuiltIn, act_id: str) -> None:
        self.spec = spec
        kind = spec.kind
        self.kind = (ARBITER if kind is _ARBITER else VOTER if kind is _VOTER
                     else SUPERPOSITION if kind is _SUPERPOSITION else PUSH
                     if kind is _PUSH_DATA else PULL if kind is _PULL_DATA else OTHER)
        # (the names interned: found by identity in the data and the mailboxes, see
        # opspec.engine.conditions.field_name)
        self.inputs: tuple[str, ...] = tuple(field_name(name) for name in spec.inputs)
        self.output: str | None = None if spec.output is None else field_name(spec.output)
        self.channel: str = field_name(spec.channel or act_id)
        self.waiting = f"pull from mailbox {self.channel!r}"


def coord_of(act: CompiledActivity, spec: CoordinationBuiltIn) -> Coord:
    """``act``'s coordination built-in ``spec`` as a :class:`Coord`, made at its first run
    and kept by the activity (``CompiledActivity.coord``; made again for another ``spec``)."""
    found: Coord | None = act.coord
    if found is None or found.spec is not spec:
        found = Coord(spec, act.id)
        act.coord = found
    return found


#: a field of neither map (:func:`inputs_of`)
_MISSING: Final = object()
#: the values of a built-in without inputs (:func:`at_once`; never changed)
_NO_VALUES: Final[list[Any]] = []


def inputs_of(scope: MutableMapping[str, Any], inputs: tuple[str, ...]) -> list[Any]:
    """The values of the fields ``inputs`` as ``scope[name]`` reads them, ``KeyError(name)``
    for one of neither map. A :class:`Scope` is read through its two dictionaries: compiled,
    ``scope[name]`` is a call of its ``__getitem__`` through Python's protocol."""
    values: list[Any] = []
    if isinstance(scope, Scope):
        fields = scope.fields
        package = scope.package
        for name in inputs:
            value = fields.get(name, _MISSING)
            if value is _MISSING:
                value = package.get(name, _MISSING)
                if value is _MISSING:
                    raise KeyError(name)
            values.append(value)
        return values
    for name in inputs:
        values.append(scope[name])
    return values


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
    built = coord_of(act, spec)
    kind = built.kind
    values = _NO_VALUES
    if built.inputs:                        # (a pull reads none: no list made for it)
        try:                                # ActivityInstance.scope without its locals
            values = inputs_of(inst.scope, built.inputs)
        except KeyError:
            return _NOT_NOW
    result: Any = None
    box: deque[Any] | None = None
    if kind == ARBITER:
        result = first_set(values)
    elif kind == VOTER or kind == SUPERPOSITION:
        try:
            result = (coord.voter(values, spec.options) if kind == VOTER
                      else coord.superposition(values, spec.weights))
        except (TypeError, ValueError):
            return _NOT_NOW
    elif kind == PULL:
        box = state.mailboxes.get(built.channel)
        if not box:
            return _NOT_NOW
    elif kind != PUSH:
        return _NOT_NOW
    state.last_key += 1                     # the key the instance would have taken
    cached = act.flag_cache                 # RunState.act_bits's cached case, in line
    if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 1:
        state.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                   act.participant)
    output = built.output
    if kind == PUSH:
        push(acts, built.channel, values[0] if len(values) == 1 else tuple(values))
    elif box is not None and output:      # (without an output the value stays, as there)
        result = _POPLEFT(box)
    if output and kind != PUSH:
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
        if isinstance(command, str):
            # (a string is set when not empty: its length read, where ``!= ""`` is a
            # comparison through Python's protocol, about three an arbiter's run)
            if len(command) > 0:
                return command
        elif command is not None and command != "":
            return command
    return None


def coordinate(acts: Activities, ai: ActivityInstance) -> None:
    """The body of a coordination built-in run as an instance: done (``body_done``), or
    waiting for a push (a pull from an empty mailbox), or failed."""
    act = ai.act
    spec = act.coordination
    assert spec is not None
    built = coord_of(act, spec)
    values = _NO_VALUES
    if built.inputs:                        # (a pull reads none: no list made for it)
        try:
            values = inputs_of(ai.scope(), built.inputs)
        except KeyError as error:
            acts.fail(ai, "coordination", f"data field {error.args[0]!r} does not exist")
            return
    kind = built.kind
    output = built.output
    try:
        if kind == ARBITER:
            result: Any = first_set(values)
        elif kind == VOTER:
            result = coord.voter(values, spec.options)
        elif kind == SUPERPOSITION:
            result = coord.superposition(values, spec.weights)
        elif kind == PUSH:
            push(acts, built.channel, values[0] if len(values) == 1 else tuple(values))
            acts.body_done(ai, None)
            return
        elif kind == PULL:
            channel = built.channel
            box = acts.state.mailboxes.get(channel)
            if box:
                acts.body_done(ai, {output: _POPLEFT(box)} if output else None)
            else:
                ai.waiting = built.waiting
                pullers = acts.state.pullers
                waiting = pullers.get(channel)
                if waiting is None:         # (setdefault's, without a deque made per call)
                    waiting = deque()
                    pullers[channel] = waiting
                _APPEND(waiting, ai)
            return
        else:
            # at once: a mode ending this instance stops all after it (its completion too)
            acts.triggers.change_mode(spec.target_mode or "", act, ai.frame.inst)
            acts.body_done(ai, None)
            return
    except (TypeError, ValueError) as error:
        acts.fail(ai, "coordination", f"{spec.kind.value} failed: {error}")
        return
    acts.body_done(ai, {output: result} if output else None)


def push(acts: Activities, channel: str, value: Any) -> None:
    """Put ``value`` into supervisor mailbox ``channel``; a waiting pull gets it."""
    state = acts.state
    pullers = state.pullers.get(channel)
    while pullers:
        ai = _POPLEFT(pullers)
        if ai.state == RUNNING:
            act = ai.act
            spec = act.coordination
            output = coord_of(act, spec).output if spec is not None else None
            state.ready.append((acts.body_done_q, ai, {output: value} if output else None,
                                None))
            return
    mailboxes = state.mailboxes
    box = mailboxes.get(channel)
    if box is None:                         # (setdefault's, without a deque made per call)
        box = deque()
        mailboxes[channel] = box
    _APPEND(box, value)
