"""The walkthrough's clock: simulated time moved at the chosen speed, paused, or skipped
(to the next event, or until something is offered to the person), the engine stepped in
slices between key presses; the pace a call from the device sets (``on_call``); and the
clock as the walkthrough shows it (:func:`clock`, :func:`time_of_day_shown`)."""

from __future__ import annotations

import math

from opspec.clock import clock_time
from opspec.tui.session_state import SessionState, guarded

__all__ = ["SessionClock", "clock", "time_of_day_shown"]


class SessionClock(SessionState):
    """The clock of a :class:`~opspec.tui.session.WalkSession` and the pace of a call."""

    # ------------------------------------------------------------------ clock state
    @property
    def speed(self) -> float:
        """Simulated seconds per wall second while the clock runs."""
        return self._speed

    @speed.setter
    def speed(self, value: float) -> None:
        if value != self._speed:
            if self._speed != 1.0:           # what waits was timed faster than real time
                self.times.spoil(f"the clock ran at {self._speed:g}x", since_before=self.now)
            self._speed = value
            self._speed_before_call = None   # the person chose: a call's end leaves it

    @property
    def paused(self) -> bool:
        return self._paused

    @paused.setter
    def paused(self, value: bool) -> None:
        if value and not self._paused:
            # the simulated clock stands while the person thinks: the durations of what
            # waits now would count that time as zero
            self.times.spoil("the clock was paused")
        self._paused = value
        if not value:
            self._call_paused = False

    def spoil_timing(self, why: str) -> None:
        """Simulated time jumped (a skip, a wait): what waits now has no real duration."""
        self.times.spoil(why)

    # ------------------------------------------------------------------ time
    @property
    def now(self) -> float:
        return float(self.sim.env.now)

    @guarded()
    def advance(self, wall_seconds: float, budget: int | None = None) -> None:
        """Let ``wall_seconds`` of real time pass at the current speed (unless paused); a
        skip in progress (or held up by a real device) goes on instead.

        ``budget`` bounds the engine events stepped in this call (``None``: no bound). The
        app passes one so that a long skip runs in slices between key presses; a skip not
        finished keeps :attr:`skipping` set and goes on at the next call."""
        if self.skipping:
            self.sim.drain_posts()
            self._skip(budget)
            return
        if self.ended:
            return
        if self.paused:
            # the clock stands still, but a device's answer is taken at the current time
            self.run_to(self.now, budget)
            return
        self.run_to(min(self.horizon, self.now + wall_seconds * self.speed), budget)

    @property
    def waiting_for_devices(self) -> bool:
        """Whether a real device (answering in wall time) has work it has not answered yet:
        skipping simulated time now would jump past its answer."""
        return self.wall_devices and bool(self.device_work)

    @guarded()
    def skip_to_next_event(self, budget: int | None = None) -> None:
        """Jump to the next scheduled event after now (not while a real device is busy)."""
        if self.waiting_for_devices or self.ended:
            return
        self.spoil_timing("skipped to the next event")
        if self.sim.peek() <= self.now:
            # what is due now happens first: the stop event SimPy's run(until) leaves queued
            # at the current time (else "next" would be that, and n would do nothing while
            # the clock runs), and anything else due now
            self._step_to(self.now, budget)
        due = self.sim.peek()
        self.run_to(min(self.horizon, due if math.isfinite(due) else self.horizon), budget)

    @guarded()
    def skip_until_user(self, budget: int | None = None) -> None:
        """Run until something is offered to the person (or the run ends). With a real
        device busy the skip pauses until it answers. With a ``budget`` (engine events per
        call) the skip may stop early with :attr:`skipping` still set: :meth:`advance` goes
        on with it, and :meth:`cancel_skip` abandons it."""
        self.spoil_timing("skipped ahead")
        self.skipping = True
        self._skip_calls = self.calls
        self._skip_from = self._offer_seq
        self._skip(budget)

    def cancel_skip(self) -> None:
        """Stop a skip in progress where it is."""
        self.skipping = False

    def _skip(self, budget: int | None = None) -> None:
        # with the lane handed over nothing waits for the person: stop at the next call
        calls = self._skip_calls
        left = budget
        # offers already there when the skip began do not stop it (the person passed them)
        while not self.has_new_offers(self._skip_from) and not self.ended and (
                not self.waiting_for_devices) and not (self.handed_over and self.calls > calls):
            due = self.sim.peek()
            target = min(self.horizon, due) if math.isfinite(due) else self.horizon
            reached, used = self._step_to(target, left)
            if not reached:
                return                      # the next slice goes on (skipping stays set)
            if left is not None:
                left -= used
                if left <= 0:
                    break
            if not math.isfinite(due):
                break
        if self.has_new_offers(self._skip_from) or self.ended or (
                self.handed_over and self.calls > calls):
            self.skipping = False

    @guarded(True)
    def run_to(self, target: float, budget: int | None = None) -> bool:
        """Step the engine to simulated time ``target`` (at most ``budget`` events); ``False``
        when the budget ran out first (the clock then stands at the last event stepped, and a
        later call goes on). It also stops, returning ``True``, where the device begins to
        call the person (the clock changes pace there: ``on_call``); step again to go on."""
        return self._step_to(min(self.horizon, target), budget)[0]

    def _step_to(self, target: float, budget: int | None) -> tuple[bool, int]:
        env = self.sim.env
        self.sim.drain_posts()
        steps = 0
        since = self._offer_seq
        # at the target time, stop at a new offer (the person sees it before what follows)
        while target > self.now or not self.has_new_offers(since):
            due = env.peek()
            if due > target or due >= self.horizon:
                break       # what falls at the end time is after the run, as in `opspec run`
            if budget is not None and steps >= budget:
                return False, steps
            env.step()
            steps += 1
            if self._call_began:
                # the device calls: the clock changes pace from here (on_call)
                self._follow_call()
                return True, steps
        if target > env.now:
            # SimPy's run(until) stops before what is due at the target (it falls after the
            # run, as in `opspec run`); it leaves its stop event queued at the target, which
            # skip_to_next_event steps past
            env.run(until=target)
        if self.now >= self.horizon - 1e-9 and not self.ended:
            self.ended = True
            self.sim.check_waiting(horizon=self.horizon)
            self._trace_run_ended()        # as opspec run's trace ends (session_record)
        return True, steps

    # ------------------------------------------------------------------ a call from the device
    @property
    def calling(self) -> bool:
        """Whether the device calls the person now: its alarm (or other signal to the
        user) is on; for a spec whose device does not signal, whether something waits for
        the person."""
        if self.device_signals:
            return self.board.ringing
        return bool(self.offers) and not self.handed_over

    @property
    def person_performs(self) -> bool:
        """Whether a person (not a model, not a recording) performs the user lane now."""
        return self.has_user_lane and not self.replaying and not self.handed_over

    def _follow_call(self) -> None:
        """Apply ``on_call`` when a call begins; give the speed back when it is over."""
        self._call_began = False
        calling = self.calling and self.person_performs and not self.ended
        if calling and not self._in_call:
            self._in_call, self._acted_in_call = True, False
            if self.on_call == "realtime" and self._speed != 1.0:
                before = self._speed
                self.speed = 1.0
                self._speed_before_call = before
            elif self.on_call == "pause" and not self._paused:
                self.paused = True
                self._call_paused = True
        elif not calling and self._in_call and (not self._acted_in_call or not self.offers):
            # over: the person let it pass, or answered and nothing waits any more
            self._in_call = False
            if self._speed_before_call is not None:
                before, self._speed_before_call = self._speed_before_call, None
                self.speed = before
            if self._call_paused and self.handed_over:
                # the call's pause was for the person: the model takes the lane at once,
                # as it takes back the speed (space resumes only what the person paused)
                self.paused = False
            self._call_paused = False

    @property
    def paused_words(self) -> str:
        """The status line's word for a paused clock: it says when the device's call paused
        it (``--on-call pause``) and how to go on, which a bare PAUSED did not."""
        if self._in_call and self.on_call == "pause" and self.calling:
            return "PAUSED: the device calls (space resumes)"
        return "PAUSED"

    @property
    def call_mode(self) -> str:
        """What the clock does during this call, in words ("" when there is no call)."""
        if not self._in_call:
            return ""
        if self._speed_before_call is not None:
            return f"real time while the device calls (was {self._speed_before_call:g}x)"
        return ""


def clock(seconds: float) -> str:
    """``d1 08:00:00``: :func:`opspec.clock.clock_time` to the whole second (the walkthrough
    shows the clock ticking, not its milliseconds)."""
    return clock_time(math.floor(seconds))


def time_of_day_shown(seconds: float) -> str:
    """``08:00:00``: :func:`clock` without its day (for day 10 and later too)."""
    return clock(seconds).split(" ", 1)[1]
