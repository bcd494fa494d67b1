"""The profile's fallback on a bound device: a command given up (its retries spent, or the
device gone) is simulated once, or its participant is simulated from then on, or the work
item fails with the participant's exception; queued work follows its participant's mode."""

from __future__ import annotations

from opspec.bindings.binding_state import BindingState, Job

__all__ = ["Fallback"]


class Fallback(BindingState):
    """What happens to work the device cannot do (a part of
    :class:`~opspec.bindings.binding.DeviceBinding`)."""

    def _give_up(self, job: Job, reason: str) -> None:
        participant = job.item.participant or ""
        fallback = self.profile.fallback_for(participant)
        if fallback.then == "simulate":
            if fallback.scope == "run":
                self._switch_to_simulated(participant, reason)
            else:
                self._note(f"{participant or self.profile.name}: {job.line!r}: {reason}; "
                           "simulated this once, the next command goes to the device")
            if not job.withdrawn:
                self._sim.offer(job.item)
        elif not job.withdrawn:
            self._session_().fail(job.item, fallback.exception,
                                  f"{self._who(job.item)}: {job.line!r} failed: {reason}")

    def _switch_to_simulated(self, participant: str, reason: str) -> None:
        if self._modes.get(participant) == "simulated":
            return
        self._modes[participant] = "simulated"
        self._note(f"{participant or self.profile.name}: {reason}; using the simulated "
                   f"{participant or self.profile.name} from now on")
        for item in [w for w in self._waiting if (w.participant or "") == participant]:
            self._waiting.remove(item)
            self._sim.offer(item)
        # commands queued for it (the line may stay held for a while) go simulated now too
        for job in [j for j in self._queue if (j.item.participant or "") == participant]:
            self._queue.remove(job)
            self._reroute(job)

    def _reroute(self, job: Job) -> None:
        """A queued job whose participant left the device: simulate it or fail it."""
        if job.withdrawn:
            return
        if self.mode(job.item.participant) == "simulated":
            self._sim.offer(job.item)
        else:
            fallback = self.profile.fallback_for(job.item.participant)
            message = f"{self._who(job.item)}: the device on {self.url} is unavailable"
            self._session_().fail(job.item, fallback.exception, message)
