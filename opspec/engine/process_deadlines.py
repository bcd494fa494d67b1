"""A workflow's own deadline (``opspec:Deadline`` of a process): armed when an instance
starts, it emits ``deadline.expired`` if the instance still runs when it falls due.

Most of them fall due after their instance ended (a robot spec's 50 ms deadline on a
workflow that takes 5 ms) and would do nothing but drain: they are scheduled with
:meth:`Timers.schedule_droppable <opspec.engine.timers.Timers.schedule_droppable>`, which
keeps them off the timer heap and drops those no longer :meth:`_Deadline.needed` where their
drain could not be seen (a step of the zero-time guard at an instant where nothing else
runs); the others run as before, in their place. Each is still counted in ``sim_events`` when
it is armed. The timed callback is an object of its own (:class:`_Deadline`, extending the
compiled ``Timed``) rather than a closure handed to :meth:`RunState.call_at
<opspec.engine.runstate.RunState.call_at>`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, final

from opspec.engine.instances import ProcessInstance
from opspec.engine.lifecycle import RUNNING, SUSPENDED
from opspec.engine.timers import Timed
from opspec.engine.trace import EventKind as EK

if TYPE_CHECKING:
    from opspec.engine.flow import Flow

__all__ = ["arm", "expired"]


def arm(flow: Flow, inst: ProcessInstance, deadline: float) -> None:
    """``inst`` started: its workflow's deadline falls due ``deadline`` seconds from now."""
    state = flow.state
    if deadline <= 0.0 and state.draining:      # RunState.call_at queues it
        _queue(flow, inst, deadline)
        return
    # RunState.call_at's timed case
    state.sim_events += 1
    # a deadline the timers dropped is used again (a robot spec drops almost all of them:
    # about 250 instructions an instance to make and free one, compiled)
    spare = state.spare
    if type(spare) is _Deadline:
        state.spare = spare.spare_next
        spare.flow = flow
        spare.inst = inst
        entry = spare
    else:
        entry = _Deadline(flow, inst)
    state.schedule_droppable(deadline if deadline > 0.0 else 0.0, entry)  # noqa: FURB136


def _queue(flow: Flow, inst: ProcessInstance, deadline: float) -> None:
    # (a function of its own: compiled, a lambda in arm would make its closure's
    # environment at every call of arm, not only here)
    flow.state.call_at(deadline, lambda: expired(flow, inst))


def expired(flow: Flow, inst: ProcessInstance) -> None:
    """The deadline fell due: if the instance still runs, ``deadline.expired``."""
    if inst.state in (RUNNING, SUSPENDED):
        proc = inst.process
        state = flow.state
        if state.wants(EK.DEADLINE_EXPIRED, proc.id, None):
            state.emit(EK.DEADLINE_EXPIRED, proc.id, inst.id, None, proc.lane, None,
                       {"deadline": proc.deadline, "scope": "process"})


@final
class _Deadline(Timed):
    """The timed callback of :func:`arm`: what ``RunState.call_at``'s ``_CallAt`` does
    for :func:`expired` (then a drain), without the closure."""

    def __init__(self, flow: Flow, inst: ProcessInstance) -> None:
        self.flow = flow
        self.inst = inst

    def go(self) -> None:
        flow = self.flow
        state = self.inst.state
        if state == RUNNING or state == SUSPENDED:
            expired(flow, self.inst)
        flow.state.drain()

    def needed(self) -> bool:
        """Whether the instance still runs (else the deadline can only drain)."""
        state = self.inst.state
        return state == RUNNING or state == SUSPENDED

    def __call__(self, _event: Any) -> None:
        self.flow.state.go_now(self)
