"""The simulated devices of a world, as one engine Performer bound by Application id."""

from __future__ import annotations

from typing import Any

from opspec.engine.performers import PerformerSession, WorkItem
from opspec.worlds.base import World

__all__ = ["WorldDevices"]


class WorldDevices:
    """Performs every application the world knows (``read_range``, ``drive``…): advances the
    world to the engine's time, runs the operation and completes the work item with its data.
    World facts are traced through the session as ``world.*`` events."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.applications: dict[str, None] = dict.fromkeys(world.applications())
        self._session: PerformerSession | None = None

    def attach(self, session: PerformerSession) -> None:
        self._session = session
        self.world.tracer = session.trace

    def offer(self, item: WorkItem) -> None:
        session = self._session
        assert session is not None, "attach() first"
        self.world.advance(session.now)
        application = item.application or item.activity
        try:
            data: dict[str, Any] = self.world.operation(application, item.data)
        except KeyError:
            session.fail(item, "DeviceError",
                         f"the simulated world has no device operation {application!r}")
            return
        session.complete(item, data or None)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        """Operations complete at once: nothing is pending to withdraw."""
