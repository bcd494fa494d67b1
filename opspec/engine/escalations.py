"""Errors and escalations thrown to the enclosing activities.

An error end event cancels the nearest enclosing sub-process or call activity with a boundary
error event for its code (:func:`throw_error`). An escalation end event or intermediate throw
escalation event hands its escalation to the nearest enclosing sub-process or call activity
with a boundary escalation event for it (BPMN 2.0 §10.4.1, Table 10.88, §13.5.3). Unlike an
error it ends nothing by itself: an interrupting catcher cancels its activity, a
non-interrupting one starts its flow beside it, and an escalation nothing catches is
"unresolved" — the thrower's path goes on."""

from __future__ import annotations

from typing import TYPE_CHECKING

from opspec.engine.instances import ActivityInstance, Frame
from opspec.engine.lifecycle import RUNNING

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledActivity
    from opspec.engine.flow import Flow

__all__ = ["throw", "throw_error"]


def throw(flow: Flow, frame: Frame, code: str) -> bool:
    """Throw escalation ``code`` ("": one without escalationRef) from ``frame``: the nearest
    enclosing running activity with a boundary escalation event for ``code``, else one without
    escalationRef, fires that event. Whether ``frame`` still runs afterwards (an interrupting
    catcher cancels it with its activity)."""
    holder = frame.owner if frame.owner is not None else frame.inst.parent
    while holder is not None:
        if holder.state == RUNNING:
            index = _catcher(holder, code)
            if index >= 0:
                flow.triggers.boundary(holder, index, None)
                break
        up = holder.frame
        holder = up.owner if up.owner is not None else up.inst.parent
    return frame.inst.state == RUNNING and (frame.owner is None
                                            or frame.owner.state == RUNNING)


def _catcher(ai: ActivityInstance, code: str) -> int:
    """The boundary escalation event of ``ai`` for ``code``, else its catch-all (no
    escalationRef, whatever their order in the file); -1 when it has neither."""
    events = ai.frame.graph.activities
    anyone = -1
    for index in ai.act.boundary:
        caught = events[index].catches_escalation
        if caught == code:
            return index
        if caught == "" and anyone < 0:
            anyone = index
    return anyone


def throw_error(flow: Flow, frame: Frame, act: CompiledActivity, code: str) -> None:
    """An error end event: the nearest enclosing sub-process or call activity with a
    boundary error event (an EXCEPTION path) for ``code``, else one catching every error,
    is cancelled and takes that path (BPMN 2.0 §10.4.1, §13.5.3). Uncaught, the error
    aborts the instance that threw it (and so its callers) with a located fault."""
    what = f"error {code!r}" if code else "an error without a code"
    holder = frame.owner if frame.owner is not None else frame.inst.parent
    while holder is not None:
        if holder.state == RUNNING and _catches(holder.act, code):
            flow.activities.fail(holder, code or "error",
                                 f"{what} thrown by end event {act.id!r}")
            return
        up = holder.frame
        holder = up.owner if up.owner is not None else up.inst.parent
    flow.abort(frame.inst, act, f"{what} thrown by this end event is caught by no "
               "boundary error event of an enclosing sub-process or call activity")


def _catches(act: CompiledActivity, code: str) -> bool:
    """Whether ``act`` has an exception path (a boundary error event) for error ``code``."""
    if act.default_exception is not None:
        return True
    return any(t.exception is None or t.exception == code for t in act.exceptions)
