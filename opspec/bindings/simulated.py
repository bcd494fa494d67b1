"""The simulated device: what a participant falls back to when its hardware is absent or gone.

It performs each operation in *simulated* time: the activity completes ``simulate.duration_s``
seconds after it is offered, with ``simulate.data`` as its data. Passive operations (no
command: a button the user presses) complete only if the profile gives them a simulated
duration; otherwise they stay offered, as with a real button nobody presses.
"""

from __future__ import annotations

from opspec.bindings.profiles import DeviceProfile
from opspec.engine.performers import PerformerSession, WorkItem

__all__ = ["ProfileSimulator"]


class ProfileSimulator:
    """A :class:`~opspec.engine.performers.Performer` playing ``profile``'s device in
    simulated time (unlike :class:`opspec.engine.SimulatedDevice`, which knows no profile and
    completes each activity after its declared duration). All calls happen on the engine's
    thread."""

    def __init__(self, profile: DeviceProfile) -> None:
        self.profile = profile
        self._session: PerformerSession | None = None
        self._active: set[int] = set()

    def attach(self, session: PerformerSession) -> None:
        self._session = session

    def offer(self, item: WorkItem) -> None:
        session = self._require_session()
        op = self.profile.operation_for(item.application, item.activity)
        if op is None:
            fallback = self.profile.fallback_for(item.participant)
            session.fail(item, fallback.exception,
                         f"the simulated {self.profile.name} has no operation for "
                         f"{item.application or item.activity!r}")
            return
        if op.command is None and op.simulate_duration_s <= 0 and not op.simulate_data:
            self._active.add(item.key)  # a passive operation nobody performs
            return
        self._active.add(item.key)
        data = dict(op.simulate_data) or None

        def done() -> None:
            if item.key in self._active:
                self._active.discard(item.key)
                session.complete(item, data)

        session.call_later(op.simulate_duration_s, done)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        self._active.discard(item.key)

    def _require_session(self) -> PerformerSession:
        if self._session is None:
            raise RuntimeError("ProfileSimulator.offer() before attach()")
        return self._session
