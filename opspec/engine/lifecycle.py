"""Life cycle of workflow and activity instances in WfMC states.

The states and the legal transitions between them are *defined and checked* with the
``transitions`` library, once per definition, when this module is first used; what each
instance stores is a small int, and a state change is one dict lookup in a table derived from
that machine. Measured (issue 3, and again here with this module's states): one
``transitions.Machine`` per instance costs 0.1-0.8 ms and 8-45 KB (0.4 ms and 8 KB with
these six states), a trigger about 11 us; the table costs 0.13-0.16 us per lookup and
nothing per instance (the state is one small int in the instance's slots).

States (WfMC): ``not_started`` -> ``running`` <-> ``suspended``; ``running`` -> ``completed``
| ``terminated`` | ``aborted``; a suspended instance may also be terminated or aborted.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Final

from opspec.errors import ExecutionError

__all__ = [
    "ABORTED",
    "COMPLETED",
    "LIFECYCLE",
    "NOT_STARTED",
    "RUNNING",
    "STATE_NAMES",
    "SUSPENDED",
    "TERMINATED",
    "TRIGGERS",
    "LifeCycle",
]

NOT_STARTED: Final = 0
RUNNING: Final = 1
SUSPENDED: Final = 2
COMPLETED: Final = 3
TERMINATED: Final = 4
ABORTED: Final = 5
STATE_NAMES = ("not_started", "running", "suspended", "completed", "terminated", "aborted")
TRIGGERS = ("start", "suspend", "resume", "complete", "terminate", "abort")

_TRANSITIONS = (
    {"trigger": "start", "source": "not_started", "dest": "running"},
    {"trigger": "suspend", "source": "running", "dest": "suspended"},
    {"trigger": "resume", "source": "suspended", "dest": "running"},
    {"trigger": "complete", "source": "running", "dest": "completed"},
    {"trigger": "terminate", "source": ["not_started", "running", "suspended"],
     "dest": "terminated"},
    {"trigger": "abort", "source": ["not_started", "running", "suspended"], "dest": "aborted"},
)


class LifeCycle:
    """A state table derived from a ``transitions.Machine`` built once.

    ``table[(state, trigger)]`` is the next state; a missing key is an illegal transition.
    """

    __slots__ = ("table",)

    def __init__(self) -> None:
        from transitions import Machine  # imported here: only the definition needs it

        machine = Machine(model=None, states=list(STATE_NAMES), transitions=list(_TRANSITIONS),
                          initial="not_started", auto_transitions=False)
        index = {name: i for i, name in enumerate(STATE_NAMES)}
        table: dict[tuple[int, str], int] = {}
        for trigger, event in machine.events.items():
            for source, transitions in event.transitions.items():
                for transition in transitions:
                    table[(index[source], trigger)] = index[str(transition.dest)]
        self.table: Mapping[tuple[int, str], int] = MappingProxyType(table)

    def next(self, state: int, trigger: str, what: str = "instance") -> int:
        """The state after ``trigger``; :class:`ExecutionError` when it is not allowed."""
        try:
            return self.table[(state, trigger)]
        except KeyError:
            allowed = sorted(t for (s, t) in self.table if s == state)
            raise ExecutionError(
                f"cannot {trigger} {what}: it is {STATE_NAMES[state]}",
                hint=("allowed now: " + ", ".join(allowed)) if allowed
                else "it has finished; nothing can change it any more") from None

    def allowed(self, state: int, trigger: str) -> bool:
        return (state, trigger) in self.table


LIFECYCLE = LifeCycle()
"""The one shared definition (building it costs about a millisecond, once per process)."""
