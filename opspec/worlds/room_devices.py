"""The room world's devices as the engine's performer, compiled: what
:class:`~opspec.worlds.device.WorldDevices` does for a :class:`~opspec.worlds.room.RoomWorld`
on the operations a robot spec uses every period (``read_range``, ``read_bump``,
``drive``), without an interpreted frame per operation.

A robot spec uses a device several times a period (the vacuum cleaner: 54,000 times an
hour); around the compiled stepping (:mod:`opspec.worlds.stepping`) the interpreted glue
(``WorldDevices.offer``, ``RoomWorld.advance``, the ``op_`` method) cost more than the
world's own work. Here the same steps run compiled, on the room's compiled state: advance the
world to the engine's time (the room traces what the stepping stops at), do the operation,
complete the item. The operations' definitions stay the room's: the bumper and the range
reading are :class:`~opspec.worlds.stepping.RoomState`'s (the range noise is drawn here as
``RoomWorld.op_read_range`` draws it), the random turn is the room's own ``op_drive``.
Anything else (the first use, which traces the initial coverage; the battery, the tag
reader, an operation the world does not know) goes to ``WorldDevices``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from opspec.engine.activities import AnswersAtOnce
from opspec.engine.workitem import WorkItem
from opspec.worlds.stepping import DONE, Normals, RoomState

__all__ = ["RoomDevices"]


class RoomDevices(AnswersAtOnce):
    """The performer of a :class:`~opspec.worlds.room.RoomWorld` (``world``) with its state
    ``state``; ``general`` is the :class:`~opspec.worlds.device.WorldDevices` of the same
    world, which does every operation not done here. The engine asks it for those
    operations directly (:class:`~opspec.engine.activities.AnswersAtOnce`), without a work
    item."""

    def __init__(self, world: Any, state: RoomState, general: Any) -> None:
        self.world = world
        self.state = state
        self.general = general
        self.applications: dict[str, None] = general.applications
        self.session: Any = None
        self.announced = False
        # the range noise's draws, a batch at a time (the world's rng settles them)
        self.normals: Normals = world.normal_draws()

    def attach(self, session: Any) -> None:
        self.session = session
        self.general.attach(session)

    def answers_at_once(self, application: str) -> bool:
        """The operations done here, once the world has announced its first state."""
        return self.announced and (application == "read_bump" or application == "drive"
                                   or application == "read_range")

    def offer(self, item: WorkItem) -> None:
        application = item.application or item.activity
        if not self.answers_at_once(application):
            self.announced = True           # WorldDevices (World.advance) announces
            self.general.offer(item)
            return
        session = self.session
        result = self.answer(application, item.data, session.now)
        session.complete(item, result or None)

    def answer(self, application: str, data: Mapping[str, Any], now: float
               ) -> dict[str, Any]:
        """One of the operations done here (:meth:`answers_at_once`) at ``now``: the world
        advanced to it, then the reading or the command. The engine asks it directly
        (``Activities._answered``); :meth:`offer` for anyone offering a work item."""
        state = self.state
        code = state.advance(now)
        if code != DONE:
            self.world.finish_advance(code, now)
        result: dict[str, Any]
        if application == "read_bump":
            result = state.read_bump()
        elif application == "read_range":
            sd = state.range_noise              # (the room's range_noise)
            if sd >= 0.0:
                # RoomWorld.op_read_range, compiled: the same draw from the room's
                # generator and the same float operations (0.0 + sd * z, then the reading)
                z = self.normals.draw()
                result = {"distance": state.read_range(0.0 + sd * z)}
            else:
                result = self.world.op_read_range(data)     # normal() refuses the sd
        else:
            if isinstance(data, dict):      # a dict's get called natively
                command = data.get("motor_cmd")
            else:                           # (a Mapping's through Python's protocol)
                command = data.get("motor_cmd")
            if type(command) is not str or not command:     # (else str() gives it back)
                command = str(command or "stop")
            if command == "turn_random":
                result = self.world.op_drive(data)
            else:
                state.command = command             # RobotWorld.op_drive
                result = {}
        return result

    def withdraw(self, item: WorkItem, reason: str) -> None:
        """Operations complete at once: nothing is pending to withdraw."""
