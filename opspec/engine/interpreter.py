"""The workflow manager and processor: tokens through compiled graphs on a simulated clock.

The interpreter is one run state and four parts, one module each, that call each other:

* :mod:`~opspec.engine.runstate` — :class:`~opspec.engine.runstate.RunState`, everything a run
  holds (instances, the ready queue, waiters, offers, kept messages, the trace listeners) and
  the primitives on it: the trace (``emit``) and the clock (``drain``, ``later``, ``call_at``);
* :mod:`~opspec.engine.flow` — tokens through the graph: process instances, transitions,
  splits, joins (AND, OR, complex), exception transitions, data assignments;
* :mod:`~opspec.engine.activities` — an activity's life: start, implementation (tasks, tools,
  scripts, subflows, activity sets, coordination), CPU time and durations, loops and
  multi-instance, completion, failure and cancellation;
* :mod:`~opspec.engine.triggers` — what happens to an activity or a workflow from outside:
  messages (kept, replied, lost), signals, timers, rules, boundary events, deadlines, start
  and end triggers, mode changes;
* :mod:`~opspec.engine.offers` — work items offered to performers (people, user models,
  devices), deferred and labelled choices, and what performers answer.

:class:`Interpreter` builds them over itself (it *is* the run state) and keeps the public
operations; :class:`~opspec.engine.simulation.Simulation` adds running, stepping and results.
The parts are compiled (mypyc) native classes: a call from one to another is a direct C call.

Design (for speed, see ``benchmarks/engine_profile.py``):

* Zero-time work never becomes a clock event. A token moving to an activity is a tuple in
  the run state's *ready queue*; ``RunState.drain`` runs them in FIFO order until none is
  left (a trampoline: no recursion however long a chain of instant activities is, and
  performers may call back into the session from inside ``offer``).
* Clock events exist only where simulated time passes: a timer, a deadline, a duration, a
  worker's CPU time, a performer's ``call_later``. They are timed callbacks on the run's
  own heap, one SimPy timeout at a time driving it (a timeout each on a plain SimPy
  environment: :mod:`opspec.engine.timers`), never a generator process per activity.
  Neither cancels a scheduled event, so a timer carries the *generation* of its activity
  instance and does nothing when the instance has moved on.
* Instantaneous activities (routes, events, tasks without a bound callable, activities with
  no implementation) run without an :class:`~opspec.engine.instances.ActivityInstance`;
  only activities that wait get one.
* Trace events are built only when some listener wants that (kind, process, activity);
  a listener with a ``raw`` method (the metrics) gets the fields without any event object.

Semantics (XPDL / SISARL, see ``docs/trace-format.md`` for what each step records):

* Joins: XOR (or none) starts the activity for every arriving token; AND waits for one token
  on *each* incoming transition and consumes one from each (per loop iteration, so cycles
  work; the last arriving branch performs the merge); OR fires as BPMN 2.0 Table 13.3 says:
  once no token elsewhere can still reach an incoming transition without a token (unless it
  can also reach one with a token), consuming one token from each incoming transition that
  has one (tokens left over make the next activation).
* Splits: XOR takes the first CONDITION that holds (or unconditional transition) in declared
  order, else the OTHERWISE transition; AND takes every unconditional transition and every
  condition that holds; OR takes every condition that holds, else OTHERWISE. No split and
  several unconditional transitions means AND. Nothing to take while transitions exist is
  an error that aborts the instance.
* Exceptions (implementation raised, performer ``fail``, deadline): the EXCEPTION transition
  naming the exception (or naming none), else DEFAULTEXCEPTION, else the instance aborts.
"""


from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import simpy

from opspec.engine import joins, plans
from opspec.engine.activities import MAX_CALL_DEPTH, Activities
from opspec.engine.compiled import CompiledActivity, CompiledPackage, CompiledProcess
from opspec.engine.config import EngineConfig
from opspec.engine.flow import Flow
from opspec.engine.instances import ActivityInstance, ProcessInstance
from opspec.engine.lifecycle import RUNNING
from opspec.engine.offers import Offers
from opspec.engine.performers import WorkItem
from opspec.engine.processors import make_processor
from opspec.engine.registry import PerformerRegistry
from opspec.engine.runstate import RunState
from opspec.engine.trace import TraceListener
from opspec.engine.triggers import MESSAGE_BUFFER, Triggers
from opspec.model import Package

__all__ = ["MAX_CALL_DEPTH", "MESSAGE_BUFFER", "Interpreter"]


class Interpreter(RunState):
    """The run state of one simulation and the parts that move it (see the module docstring).

    The public face is :class:`opspec.engine.simulation.Simulation`, which adds running,
    stepping and results.
    """

    activities: Activities
    triggers: Triggers
    offers: Offers

    def __init__(self, compiled: CompiledPackage, config: EngineConfig, *,
                 performers: PerformerRegistry, seed: int, listeners: list[TraceListener],
                 params: Mapping[str, Any] | None, env: simpy.Environment | None,
                 scope: tuple[int, ...],
                 mode_loader: Callable[[str], CompiledPackage | Package] | None) -> None:
        super().__init__(compiled, config, performers=performers, seed=seed,
                         listeners=listeners, params=params, env=env, scope=scope,
                         mode_loader=mode_loader)
        flow = self.flow = Flow(self)
        activities = self.activities = Activities(self)
        triggers = self.triggers = Triggers(self)
        offers = self.offers = Offers(self)
        for part in (flow, activities, triggers, offers):
            part.connect(flow, activities, triggers, offers)
        # the processor model (opspec/engine/processors.py) and the switch cost the engine
        # adds to each general activity (0 where the model charges its own switches)
        self.pool = make_processor(self.env, config, activities.after_cpu, _alive, self.timer)
        self.switch = self.pool.activity_switch if self.pool is not None else 0.0
        # from source, each workflow's first token as straight-line code (engine/plans.py)
        plans.attach(compiled)

    # ------------------------------------------------------------------ instances
    def start_process(self, proc: CompiledProcess, data: Mapping[str, Any] | None = None, *,
                      parent: ActivityInstance | None = None, trigger: str | None = None
                      ) -> ProcessInstance:
        """Create and start an instance of ``proc`` (its start activities are queued)."""
        self.sync()
        return self.flow.start_process(proc, data, parent=parent, trigger=trigger)

    def end_instance(self, inst: ProcessInstance, state: int, reason: str,
                     notify_parent: bool = True) -> None:
        """Terminate or abort ``inst`` (see :meth:`opspec.engine.flow.Flow.end_instance`)."""
        self.sync()
        self.flow.end_instance(inst, state, reason, notify_parent)

    def abort(self, inst: ProcessInstance, act: CompiledActivity | None, message: str) -> None:
        """Abort ``inst`` with a located message (recorded as a fault); the run goes on."""
        self.sync()
        self.flow.abort(inst, act, message)

    def report_deadlock(self, inst: ProcessInstance, waiting: list[str], why: str) -> None:
        """Record a deadlock of ``inst`` (trace + summary) and abort it."""
        self.sync()
        joins.report_deadlock(self.flow, inst, waiting, why)

    # ------------------------------------------------------------------ triggers
    def broadcast(self, kind: str, name: str, data: Mapping[str, Any] | None,
                  inst: ProcessInstance | None = None, act: CompiledActivity | None = None
                  ) -> None:
        """Raise a signal or send a message (:meth:`opspec.engine.triggers.Triggers.broadcast`)."""
        self.sync()
        self.triggers.broadcast(kind, name, data, inst, act)

    def terminate_all(self, process_id: str, reason: str) -> None:
        self.sync()
        self.triggers.terminate_all(process_id, reason)

    def is_active(self, process_id: str) -> bool:
        """Whether ``process_id`` belongs to no mode or to the current mode."""
        return self.triggers.is_active(process_id)

    def change_mode(self, mode: str, act: CompiledActivity | None = None,
                    inst: ProcessInstance | None = None) -> None:
        """Switch the active workflow set (:meth:`opspec.engine.triggers.Triggers.change_mode`)."""
        self.sync()
        self.triggers.change_mode(mode, act, inst)

    def push_data(self, channel: str, value: Any) -> None:
        """Put ``value`` into supervisor mailbox ``channel``; a waiting pull gets it."""
        self.sync()
        self.activities.push_data(channel, value)

    # ------------------------------------------------------------------ performers' answers
    def performer_complete(self, item: WorkItem, data: Mapping[str, Any] | None,
                           choice: str | None) -> None:
        self.offers.performer_complete(item, data, choice)    # (it reads the clock itself)

    def performer_omit(self, item: WorkItem, reason: str) -> None:
        self.sync()
        self.offers.performer_omit(item, reason)

    def performer_fail(self, item: WorkItem, exception: str, message: str) -> None:
        self.sync()
        self.offers.performer_fail(item, exception, message)


def _alive(ai: ActivityInstance) -> bool:
    return ai.state == RUNNING
