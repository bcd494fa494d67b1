"""The timed callbacks of a run's clock: what :meth:`RunState.later
<opspec.engine.runstate.RunState.later>`, :meth:`~opspec.engine.runstate.RunState.call_at`,
:meth:`~opspec.engine.runstate.RunState.timer` and
:meth:`~opspec.engine.runstate.RunState.call_at_with` put on the heap (or hand SimPy as a
timeout's callback).

Each is one small object with the call's arguments as its fields, not a closure or a
``functools.partial`` (one allocation, not two; compiled, its ``go`` is a native method the
heap calls). Their fields are stored by the run state itself from source (see
``RunState.later``), so an entry is made without a Python frame for its ``__init__``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, final

from opspec.engine.lifecycle import RUNNING
from opspec.engine.timers import Timed

if TYPE_CHECKING:
    from opspec.engine.instances import ActivityInstance
    from opspec.engine.runstate import RunState

__all__ = ["CallAt", "CallWith", "Later"]


@final
class Later(Timed):
    """The timed callback of :meth:`RunState.later` (not a closure: one allocation, not two)."""

    def __init__(self, state: RunState, fn: Callable[[ActivityInstance, Any], None],
                 ai: ActivityInstance, arg: Any) -> None:
        self.state = state
        self.fn = fn
        self.ai = ai
        self.arg = arg
        self.gen = ai.gen

    def go(self) -> None:
        ai = self.ai
        # RunState.fired's first test, here: a deadline that lost its race (the user
        # reported in time) is due after its activity instance moved on, once a dose cycle
        if ai.gen == self.gen and ai.state == RUNNING:
            self.state.fired(self.fn, ai, self.arg, self.gen)

    def __call__(self, _event: Any) -> None:
        self.state.fire(self.fn, self.ai, self.arg, self.gen)


@final
class CallAt(Timed):
    """The timed callback of :meth:`RunState.call_at` and :meth:`RunState.timer`."""

    def __init__(self, state: RunState, callback: Callable[[], None], drain: bool) -> None:
        self.state = state
        self.callback = callback
        self.drain = drain

    def go(self) -> None:
        self.callback()
        if self.drain:
            state = self.state
            if (state.ready or state.pending or state.draining or state.now != state.instant
                    or state.instant_steps >= state.max_instant_steps):
                state.drain()
            else:                   # (drain's case of nothing queued at this instant)
                state.instant_steps += 1

    def __call__(self, _event: Any) -> None:
        self.state.called(self.callback, self.drain)


@final
class CallWith(Timed):
    """The timed callback of :meth:`RunState.call_at_with`."""

    def __init__(self, state: RunState, fn: Callable[[Any, Any, Any], None],
                 a: Any, b: Any, c: Any) -> None:
        self.state = state
        self.fn = fn
        self.a = a
        self.b = b
        self.c = c

    def go(self) -> None:
        fn = self.fn    # (read as a field, then called: from source a method load of a
        fn(self.a, self.b, self.c)      # field is never specialised)
        state = self.state
        # drain's case of nothing queued at this instant in line: a step counted (the
        # callback, a performer's answer, has drained what it queued as a rule)
        if (state.ready or state.pending or state.draining or state.now != state.instant
                or state.instant_steps >= state.max_instant_steps):
            state.drain()
        else:
            state.instant_steps += 1

    def __call__(self, _event: Any) -> None:
        self.state.go_now(self)
