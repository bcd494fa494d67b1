"""The simulated devices of a world, as one engine Performer bound by Application id."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from opspec.engine.performers import PerformerSession, WorkItem
from opspec.worlds.base import World
from opspec.worlds.room import RoomWorld
from opspec.worlds.room_devices import RoomDevices

__all__ = ["WorldDevices", "devices_of"]


class WorldDevices:
    """Performs every application the world knows (``read_range``, ``drive``…): advances the
    world to the engine's time, runs the operation and completes the work item with its data.
    World facts are traced through the session as ``world.*`` events."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.applications: dict[str, None] = dict.fromkeys(world.applications())
        self._session: PerformerSession | None = None
        # Application id -> the world's bound ``op_`` method, looked up once (World.operation
        # builds the name and looks it up on every call); a world that answers operations its
        # own way (overrides ``operation``) is asked every time
        self._handlers: dict[str, Callable[[Mapping[str, Any]], dict[str, Any]]] | None = (
            {} if type(world).operation is World.operation else None)

    def attach(self, session: PerformerSession) -> None:
        self._session = session
        self.world.tracer = session.trace

    def offer(self, item: WorkItem) -> None:
        session = self._session
        assert session is not None, "attach() first"
        world = self.world
        world.advance(session.now)
        application = item.application or item.activity
        handlers = self._handlers
        handler = None if handlers is None else handlers.get(application)
        if handler is None and handlers is not None:
            handler = getattr(world, f"op_{application}", None)
            if handler is not None:
                handlers[application] = handler
        try:
            data: dict[str, Any] = (world.operation(application, item.data) if handler is None
                                    else handler(item.data))
        except KeyError:
            session.fail(item, "DeviceError",
                         f"the simulated world has no device operation {application!r}")
            return
        session.complete(item, data or None)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        """Operations complete at once: nothing is pending to withdraw."""


def devices_of(world: World) -> WorldDevices | RoomDevices:
    """The performer of ``world``'s devices: :class:`WorldDevices`, or for a room world as
    it is (not a subclass, which may step or answer its own way) the compiled
    :class:`~opspec.worlds.room_devices.RoomDevices` in front of it."""
    general = WorldDevices(world)
    if type(world) is RoomWorld:
        return RoomDevices(world, world._state, general)
    return general
