"""An activity's tools (XPDL ``Tool`` / ``TaskApplication``): run in declared order as the
activity's body, each offered to the performer its application is bound to, or run as a
script, or done at once; and a performer's results mapped back onto the data fields through
the formal parameters. Functions of :class:`~opspec.engine.activities.Activities`, which runs
a task's toolchain as its body (``Activities._body``) and queues :func:`done` when a tool's
performer answers (``Activities.tool_done``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from opspec.engine.instances import ActivityInstance
from opspec.engine.lifecycle import RUNNING, SUSPENDED
from opspec.engine.runstate import discard
from opspec.errors import OpspecError
from opspec.model import ParameterMode

if TYPE_CHECKING:
    from opspec.engine.activities import Activities

__all__ = ["done", "outputs", "run"]

#: an activity's or a tool's actual parameters: (mode, formal, value function, target field)
Params = tuple[tuple[ParameterMode, str, Any, str | None], ...]


def run(acts: Activities, ai: ActivityInstance, index: int) -> None:
    """Run the task's tools from ``index`` on, in order (XPDL: every ``Tool`` of the
    activity). A tool whose application is bound to a performer is offered to it as a
    work item, and the next tool runs when that completes; a script tool runs its
    statements; any other tool completes at once. The body is done after the last."""
    state = acts.state
    tools = ai.act.tools
    while index < len(tools):
        tool = tools[index]
        performer = state.apps.get(tool.application)
        if performer is not None:
            data = acts.inputs(ai, tool.params)
            if data is None:
                return
            key = ai.key
            table = state.tool_at
            if key not in table:
                ai.on_leave(lambda: discard(table, key))  # noqa: B023 - returns below
            table[key] = index
            acts.offers.offer(ai, performer, (), data, None, tool.application)
            return
        if tool.script is not None and not _script(acts, ai, tool.application,
                                                   tool.params, tool.script):
            return
        index += 1
    state.ready.append((acts.body_done_q, ai, None, None))


def done(acts: Activities, ai: ActivityInstance, data: Mapping[str, Any] | None) -> None:
    """The performer of one tool completed: its outputs, then the next tool."""
    if ai.state != RUNNING:
        return
    inst = ai.frame.inst
    if inst.state == SUSPENDED:
        inst.defer((acts.tool_done, ai, data, None))
        return
    index = acts.state.tool_at.pop(ai.key, 0)
    if data:
        for key, value in outputs(ai, data, ai.act.tools[index].params).items():
            acts.flow.set_field(inst, ai.act, key, value)
    run(acts, ai, index + 1)


def outputs(ai: ActivityInstance, data: Mapping[str, Any],
            params: Params | None = None) -> dict[str, Any]:
    """Map a performer's results (by formal parameter id) onto the actual data fields;
    keys that are not formal parameters are taken as data field names."""
    out: dict[str, Any] = {}
    if params is None:
        params = ai.act.params
    formal_to_target = {f: t for mode, f, _fn, t in params
                        if mode is not ParameterMode.IN and t is not None}
    inputs_only = {f for mode, f, _fn, _t in params if mode is ParameterMode.IN}
    for key, value in data.items():
        if key in formal_to_target:
            out[formal_to_target[key]] = value
        elif key not in inputs_only:
            out[key] = value
    return out


def _script(acts: Activities, ai: ActivityInstance, application: str, params: Params,
            script: tuple[tuple[str, Any], ...]) -> bool:
    """A script tool agent's application, run as a built-in: IN/INOUT formals take the
    actual parameters' values (OUT formals start unset), the statements run in order,
    OUT/INOUT formals are written back to the actual parameters' data fields."""
    inst = ai.frame.inst
    now = acts.state.now
    local: dict[str, Any] = {}
    reads = ai.scope()
    try:
        for _mode, formal, fn, _target in params:
            local[formal] = fn(reads, now) if fn is not None else None
        for variable, fn in script:
            local[variable] = fn(local, now)
    except OpspecError as error:
        acts.fail(ai, "script", f"the script of application {application!r} failed: "
                  f"{error.message}")
        return False
    for mode, formal, _fn, target in params:
        if mode is not ParameterMode.IN and target is not None:
            acts.flow.set_field(inst, ai.act, target, local.get(formal))
    return True
