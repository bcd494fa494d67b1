"""A walkthrough session without any UI: the engine, the person's lane, the clock, the record.

The Textual app (:mod:`opspec.tui.app`) is a view of this object and sends it the person's
actions; tests drive it directly too. Everything here runs on the caller's thread (the app's
event loop): SimPy is stepped, never run from another thread.

- **Time**: :meth:`advance` moves simulated time by ``wall_seconds × speed`` (nothing happens
  while paused); :meth:`skip_to_next_event` jumps to the next scheduled event;
  :meth:`skip_until_user` runs until something is offered to the person (or the run ends).
- **When the device calls the person** (its alarm rings, or something is offered to a person
  whose device does not signal) the clock drops to real time (``on_call="realtime"``, the
  default), pauses (``"pause"``) or goes on as it was (``"keep"``), so a person can answer
  the first alarm. The speed comes back when the call is over: at once if the person let it
  pass, else when nothing waits for them any more.
- **Response times** (:mod:`opspec.tui.timing`): every offer remembers when it reached the
  person, in simulated and wall time, and whether the clock has run in real time since; the
  recorded action says how long the person took (wall seconds) and whether the simulated
  duration is usable for ``opspec fit``.
- **The person's lane**: work items offered to the user lane wait in :attr:`offers` until the
  person acts (:meth:`act`) — or the device withdraws them (a deadline, another branch). With
  :meth:`hand_over` a user model performs the lane; :meth:`take_back` returns it.
- **Recording**: every action (the person's or the model's while handed over) is written at
  once to the recording (a script file ``opspec run --script`` and the test helpers replay),
  and every trace event to ``<recording>.trace.jsonl`` (for ``opspec fit``).
- **A run that fails** (an :class:`~opspec.errors.ExecutionError` from the engine, such as a
  zero-time cycle: the simulated clock stopped advancing) ends the session: :attr:`failure`
  holds the error, :attr:`ended` is set, the timeline shows it as an engine fault, and
  ``opspec walkthrough`` prints it in one line and exits 1 when the app closes.
"""

from __future__ import annotations

import functools
import json
import math
import os
import statistics
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from opspec.clock import clock_time
from opspec.engine.compiled import K_GATEWAY, K_NOOP, CompiledPackage
from opspec.engine.lanes import all_activities, user_lane
from opspec.engine.performers import PerformerSession, WorkItem
from opspec.engine.simulation import Simulation
from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError, ExecutionError
from opspec.tui.devices import DeviceBoard
from opspec.tui.feedback import Aftermath
from opspec.tui.lane import LaneUser, Offer
from opspec.tui.replay import tagged_action
from opspec.tui.summary import metric_lines, replay_commands, response_lines
from opspec.tui.timing import OfferTimes, Response

if TYPE_CHECKING:
    from opspec.runs import RunOutcome

__all__ = ["ON_CALL", "Offer", "WalkSession"]

#: what the clock does when the device calls the person (``--on-call``)
ON_CALL = ("realtime", "pause", "keep")

_F = TypeVar("_F", bound=Callable[..., Any])


def _guarded(default: Any = None) -> Callable[[_F], _F]:
    """Methods that step the engine: an ExecutionError ends the session (see
    :meth:`WalkSession._fail`) and the method returns ``default``."""
    def wrap(method: _F) -> _F:
        @functools.wraps(method)
        def guarded(self: WalkSession, *args: Any, **kwargs: Any) -> Any:
            if self.failure is not None:
                return default
            try:
                return method(self, *args, **kwargs)
            except ExecutionError as error:
                self._fail(error)
                return default
        return guarded  # type: ignore[return-value]
    return wrap

DAY = 86_400.0
_ANSWERED = frozenset({"activity.completed", "activity.omitted", "activity.failed",
                       "activity.withdrawn", "activity.aborted", "deadline.expired"})


class WalkSession:
    """One walkthrough (see the module docstring)."""

    def __init__(self, compiled: CompiledPackage, *, seed: int = 0, days: float | None = None,
                 record: str | Path | None = None, model_factory: Callable[[], Any] | None = None,
                 performers: Mapping[str, Any] | None = None, config: Any = None,
                 replay: Any = None, spec_path: str = "",
                 device_participants: Mapping[str, Sequence[str]] | None = None,
                 wall_devices: bool = False, on_call: str = "realtime",
                 person: str | None = None) -> None:
        from opspec.run_rules import check_seed, run_length

        self.compiled = compiled
        self.seed = check_seed(seed)
        #: where the run ends: the one rule of every run (opspec.runs.run_length): ``days``,
        #: else the spec's opspec:RunLength, else one day
        self.horizon = run_length(compiled, days=days)
        if on_call not in ON_CALL:
            raise ConfigurationError(f"--on-call takes one of {', '.join(ON_CALL)}, not "
                                     f"{on_call!r}")
        self.on_call = on_call
        #: when each offer reached the person, and whether the clock ran in real time since
        self.times = OfferTimes()
        self._speed = 60.0
        self._paused = False
        #: the speed the person had before a call dropped the clock to real time
        self._speed_before_call: float | None = None
        self._in_call = False                # the device calls the person now
        self._acted_in_call = False          # ... and the person has answered something
        self._call_began = False             # set by an event: stop stepping, apply on_call
        #: the person's actions with their response times (the end-of-run summary)
        self.responses: list[Response] = []
        self.model_factory = model_factory
        self.events: deque[TraceEvent] = deque(maxlen=2000)
        self.listeners: list[Callable[[TraceEvent], None]] = []
        self.deadlines: dict[tuple[int, str], float] = {}   # (instance, activity) -> due time
        self.current: dict[int, tuple[str, str]] = {}       # instance -> (process, activity)
        self.participants: dict[str, str] = {}              # participant -> last action
        #: each device participant's state (ringing, busy, last done, display, fault)
        self.board = DeviceBoard(compiled, device_participants)
        self.replaying = replay is not None
        #: real devices are bound: their answers come in wall time (see waiting_for_devices)
        self.wall_devices = wall_devices
        self.device_work: set[tuple[int, str]] = set()      # offered to a device, unanswered
        self.skipping = False                               # a skip until the user goes on
        self._skip_calls = 0                                # self.calls when it began
        self.calls = 0                                      # user-lane processes started
        #: what the person can do now, oldest first (offers of an instance that ended, or
        #: superseded by the same activity offered in a newer instance, are gone)
        self.offers: list[Offer] = []
        self.lapsed = 0                                     # offers superseded so far
        self._offer_seq = 0                                 # offers made so far
        self._seq_of: dict[int, int] = {}                   # item key -> its offer number
        self._skip_from = 0                                 # _offer_seq when the skip began
        self.ended = False
        #: instances whose every offer to the person lapsed (not shown as running)
        self.lapsed_instances: set[int] = set()
        #: the error that ended the run (a zero-time cycle...), or None
        self.failure: ExecutionError | None = None
        self.spec_path = spec_path
        self.person = person
        self._outcome: RunOutcome | None = None
        self.record_path = Path(record) if record is not None else None
        self._steps: list[list[str]] = []
        self._trace_file = None
        if self.record_path is not None:
            trace_path = self.record_path.with_suffix(".trace.jsonl")
            try:
                self.record_path.parent.mkdir(parents=True, exist_ok=True)
                self._write_record()
                from opspec.engine.trace_sinks import JsonlSink

                header: dict[str, Any] = {"spec": spec_path, "seed": seed, "walkthrough": True}
                if person is not None:
                    # whose session this is: opspec fit counts a participant's sessions as
                    # one person (docs/trace-format.md, "person")
                    header["person"] = person
                self._trace_file = JsonlSink(trace_path, header, flush_every=1)
            except OSError as error:
                raise ConfigurationError(
                    f"cannot write the recording {self.record_path}: "
                    f"{error.strerror or error}",
                    hint="give --record a path in a folder you can write to, or --no-record"
                ) from None
        activities = list(all_activities(compiled))
        self._deadline_of = {(a.process, a.id): a.deadlines for a in activities
                             if a.deadlines}
        #: the spec's names for activities (choices are shown by name, not id)
        self._names = {(a.process, a.id): a.label or a.id for a in activities}
        #: what the person's last action led to (shown under the offers)
        self.aftermath = Aftermath(self._label_of, quiet={
            (a.process, a.id) for a in activities
            if a.kind in (K_NOOP, K_GATEWAY) and a.sampler is None and not a.raises})
        #: the device signals the user (an alarm raising a trigger): the banner follows it
        self.device_signals = any(a.raises is not None and not a.user_lane
                                  for a in activities)
        lane = user_lane(compiled)
        #: the spec has manual activities for the person (vacuum robots may have none)
        self.has_user_lane = not lane.empty
        self.lane_user = LaneUser(self)
        from opspec.runs import User, build

        # the walkthrough is user 0 of its seed, built as every run is (opspec.runs): the
        # world, the mode loader, the random scope (0,) are those of `opspec run --seed`
        user = (User.script(replay, "the recording") if replay is not None
                else User.person(self.lane_user))
        listeners: list[Any] = [self.board, self._on_event]
        if self._trace_file is not None:
            listeners.append(self._trace_file)
        self.run = build(compiled, seed=self.seed, user=user, until=self.horizon,
                         config=config, performers=performers, listeners=listeners)
        self.sim: Simulation = self.run.sim
        self._boot()

    @_guarded()
    def _boot(self) -> None:
        self.sim.boot()
        self._follow_call()

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

    def spoil_timing(self, why: str) -> None:
        """Simulated time jumped (a skip, a wait): what waits now has no real duration."""
        self.times.spoil(why)

    def _fail(self, error: ExecutionError) -> None:
        """The engine cannot go on: end the session and show why (as an engine fault)."""
        self.failure = error
        self.ended = True
        self.skipping = False
        at = error.sim_time if error.sim_time is not None else self.now
        self._on_event(TraceEvent(at, "fault", lane="device", package=self.compiled.id,
                                  data={"device": "engine", "fault": str(error),
                                        "message": str(error)}))

    # ------------------------------------------------------------------ time
    @property
    def now(self) -> float:
        return float(self.sim.env.now)

    @_guarded()
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

    @_guarded()
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

    @_guarded()
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

    def has_new_offers(self, since: int) -> bool:
        """Whether an offer made after the ``since``-th one is waiting for the person."""
        return any(self._seq_of.get(o.item.key, 0) > since for o in self.offers)

    @_guarded(True)
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
        return True, steps

    # ------------------------------------------------------------------ the person
    @_guarded()
    def act(self, offer: Offer) -> None:
        """The person does ``offer`` now."""
        engine = self._take(offer, offer.action, offer.label)
        if engine is not None:
            engine.complete(offer.item, None, offer.choice)
            self._follow_call()

    @_guarded()
    def ignore(self, offer: Offer) -> None:
        """The person explicitly does not do ``offer`` (omission)."""
        engine = self._take(offer, tagged_action("omit", offer.item.activity,
                                                 offer.item.instance), f"not: {offer.label}")
        if engine is not None:
            engine.omit(offer.item, "the person chose not to")
            self._follow_call()

    def _take(self, offer: Offer, action: str, label: str) -> PerformerSession | None:
        """The person answers ``offer`` with ``action``: recorded and the offer withdrawn;
        the lane's engine to tell, or None when the offer no longer stands (the run ended,
        the lane was handed over, or it was answered already)."""
        engine = self.lane_user.engine
        if engine is None or self.ended or self.handed_over or (
                offer.item.key not in self.lane_user.items):
            return None
        self.lane_user.items.pop(offer.item.key, None)
        self._record(action, by="person", item=offer.item, label=label)
        self._drop_offers(offer.item.key)
        return engine

    @_guarded(False)
    def hand_over(self) -> bool:
        """Let the user model perform the lane from now on, starting with what the person
        is offered now (``False``: no model, or a replay performs the lane)."""
        if self.model_factory is None or self.replaying or self.handed_over:
            return False
        current = list({o.item.key: o.item for o in self.offers}.values())
        self.offers.clear()
        self.lane_user.hand_over(self.model_factory(), current)
        return True

    @_guarded()
    def take_back(self) -> None:
        """The person performs the lane again: the model's pending work is withdrawn from
        it (a delayed action of the model does nothing) and offered to the person."""
        if not self.handed_over:
            return
        for item in self.lane_user.take_back():
            self._offered(item)
            # offered to the engine long ago: its duration is not the person's
            self.times.spoil("taken back from the user model", keys=(item.key,))

    @property
    def handed_over(self) -> bool:
        return self.lane_user.model is not None

    @property
    def calling(self) -> bool:
        """Whether the device calls the person now: its alarm (or other signal to the
        user) is on; for a spec whose device does not signal, whether something waits for
        the person."""
        if self.device_signals:
            return self.board.ringing
        return bool(self.offers) and not self.handed_over

    def _label_of(self, process: str, activity: str) -> str:
        return self._names.get((process, activity), activity)

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
            elif self.on_call == "pause":
                self.paused = True
        elif not calling and self._in_call and (not self._acted_in_call or not self.offers):
            # over: the person let it pass, or answered and nothing waits any more
            self._in_call = False
            if self._speed_before_call is not None:
                before, self._speed_before_call = self._speed_before_call, None
                self.speed = before

    @property
    def call_mode(self) -> str:
        """What the clock does during this call, in words ("" when there is no call)."""
        if not self._in_call:
            return ""
        if self._speed_before_call is not None:
            return f"real time while the device calls (was {self._speed_before_call:g}x)"
        return ""

    # ------------------------------------------------------------------ engine side
    def _offered(self, item: WorkItem) -> None:
        # the same activity offered in a newer instance supersedes the older offer (three
        # ignored alarms leave one "Hear the alarm", the newest); the older one is not
        # done, it lapses as an untaken action does
        stale = {o.item.key for o in self.offers
                 if o.item.process == item.process and o.item.activity == item.activity
                 and o.item.instance != item.instance}
        if stale:
            self.lapsed += len(stale)
            lapsed = {o.item.instance for o in self.offers if o.item.key in stale}
            for key in stale:
                self.lane_user.items.pop(key, None)
            self._drop_offers(*stale)
            # an instance with nothing left for the person has lapsed: it is not running
            # any more as far as the person can tell (it waits for an answer that will not
            # come), so it leaves the Running list
            for instance in lapsed - {i.instance for i in self.lane_user.items.values()}:
                self.current.pop(instance, None)
                self.deadlines = {k: v for k, v in self.deadlines.items() if k[0] != instance}
                self.lapsed_instances.add(instance)
        self._offer_seq += 1
        self._seq_of[item.key] = self._offer_seq
        self.times.shown(item.key, self.now, paused=self._paused)
        if item.choices:
            self.offers.extend(Offer(item, choice, self._names.get((item.process, choice)))
                               for choice in item.choices)
        else:
            self.offers.append(Offer(item, None))

    def _drop_offers(self, *keys: int) -> None:
        self.offers = [o for o in self.offers if o.item.key not in keys]
        for key in keys:
            self._seq_of.pop(key, None)
            self.times.forget(key)

    def _drop_instance(self, instance: int) -> None:
        """An instance ended: what it offered the person goes."""
        gone = [k for k, i in self.lane_user.items.items() if i.instance == instance]
        for key in gone:
            self.lane_user.items.pop(key, None)
        self._drop_offers(*gone, *(o.item.key for o in self.offers
                                   if o.item.instance == instance))

    def _on_event(self, event: TraceEvent) -> None:
        self.events.append(event)
        kind = event.kind
        if kind == "activity.withdrawn" and event.activity:
            gone = [o.item.key for o in self.offers if o.item.instance == event.instance
                    and o.item.activity == event.activity]
            self._drop_offers(*gone)
            self.lane_user.items = {k: i for k, i in self.lane_user.items.items() if not (
                i.instance == event.instance and i.activity == event.activity)}
        if event.instance is not None and event.activity and event.lane != "user":
            if kind == "activity.offered":
                self.device_work.add((event.instance, event.activity))
            elif kind in _ANSWERED:
                self.device_work.discard((event.instance, event.activity))
        if event.instance is not None and event.activity and (
                event.instance not in self.lapsed_instances):
            if kind in ("activity.started", "activity.offered"):
                self.current[event.instance] = (event.process or "", event.activity)
                for seconds, _sync, _exc in self._deadline_of.get(
                        (event.process or "", event.activity), ()):
                    try:
                        due = float(seconds({}, event.time))
                    except Exception:  # noqa: BLE001, S112 - a data-dependent deadline: not shown
                        continue
                    self.deadlines[(event.instance, event.activity)] = event.time + due
            elif kind in ("activity.completed", "deadline.expired", "activity.withdrawn",
                          "activity.aborted", "activity.omitted"):
                self.deadlines.pop((event.instance, event.activity), None)
        if kind.startswith("process.") and kind != "process.started" and (
                event.instance is not None):
            self._drop_instance(event.instance)
            self.device_work = {w for w in self.device_work if w[0] != event.instance}
            self.current.pop(event.instance, None)
            self.deadlines = {k: v for k, v in self.deadlines.items()
                              if k[0] != event.instance}
        if kind == "activity.completed" and event.participant and event.lane != "user":
            self.participants[event.participant] = (
                f"{event.activity} at {time_of_day_shown(event.time)}")
        if kind in ("fault", "device.note"):
            data = event.data or {}
            who = str(data.get("participant") or data.get("device") or "device")
            prefix = "FAULT: " if kind == "fault" else "note: "
            self.participants[who] = prefix + str(data.get("message", ""))
        if kind == "process.started" and event.lane == "user":
            self.calls += 1
        self.aftermath(event)
        if not self._in_call and self.calling and self.person_performs:
            self._call_began = True          # the stepping loop stops and applies on_call
        elif self._in_call and not self.calling:
            self._follow_call()
        for listener in self.listeners:
            listener(event)

    # ------------------------------------------------------------------ recording
    def _record(self, action: str, *, by: str, item: WorkItem | None = None,
                label: str = "") -> None:
        """Write ``action`` to the recording and the trace. For an offered ``item`` the trace
        says how long the person took (``response_wall_s``, wall seconds since the offer
        reached them) and whether the simulated duration is real (``usable``: the clock ran
        in real time throughout; else ``why`` not), which ``opspec fit`` honours."""
        self._steps.append([f"at {self.now!r}", action])
        self._write_record()
        data: dict[str, Any] = {"action": action, "by": by,
                                "wall": time.time()}          # wall-clock: the record
        if item is not None:
            response = self.times.answered(item.key, self.now, by=by, paused=self._paused,
                                           speed=self._speed)
            data.update(instance=item.instance, activity=item.activity,
                        **response.trace_data())
            if by == "person":
                self.responses.append(response.named(label or item.activity, self.now))
                self._acted_in_call = self._in_call or self._acted_in_call
                self.aftermath.acted(label or item.activity, item, self.now)
        self.sim.session.trace("walkthrough.action", data)

    def _write_record(self) -> None:
        if self.record_path is None:
            return
        # one step per line: readable, and diffable between two sessions
        steps = ",\n  ".join(json.dumps(step) for step in self._steps)
        text = ('{"otherwise": "wait", "steps": [' + (f"\n  {steps}\n" if steps else "")
                + "]}\n")
        tmp = self.record_path.with_suffix(self.record_path.suffix + ".tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, self.record_path)

    # ------------------------------------------------------------------ the end
    def outcome(self) -> RunOutcome | None:
        """What the run produced so far, as ``opspec run`` reports it (taken once: at the
        end of the run, or when the person quits before it); ``None`` after a failure."""
        if self._outcome is None and self.failure is None:
            self._outcome = self.run.outcome()
        return self._outcome

    def summary_lines(self, *, final: bool = True) -> list[str]:
        """The session in words: when, the spec's metrics (the numbers
        ``opspec run SPEC --script RECORDING`` prints), the person's response times, and
        where the recording is with the commands that replay it. ``final``: the end of the
        session (the run's outcome is taken, once); else the numbers so far, with the run
        going on."""
        if self.failure is not None:
            head = f"The run failed at {clock(self.now)}: {self.failure}"
        elif self.ended:
            head = f"The run ended at {clock(self.horizon)}."
        elif final:
            head = (f"Stopped at {clock(self.now)}, before the end of the run "
                    f"({clock(self.horizon)}).")
        else:
            head = f"So far, at {clock(self.now)} (the run ends at {clock(self.horizon)})."
        lines = [head]
        metrics: Mapping[str, Mapping[str, Any]] = {}
        medians: Mapping[str, float] = {}
        if final or self.ended:
            outcome = self.outcome()
            if outcome is not None:
                metrics, medians = outcome.metrics, outcome.medians
        elif self.failure is None:
            # the numbers so far, without ending the run's monitors
            metrics = self.sim.result().metrics
            samples = self.sim.metrics.samples if self.sim.metrics is not None else {}
            medians = {k: statistics.median(v) for k, v in samples.items() if v}
        if metrics:
            lines += ["", "The spec's metrics (as opspec run prints them):",
                      *metric_lines(metrics, medians)]
        if self.has_user_lane and not self.replaying:
            lines += ["", "Your response times (wall clock, from the offer to your key):",
                      *response_lines(self.responses)]
        if self.record_path is not None:
            walk, run = replay_commands(self.spec_path or "SPEC", self.record_path)
            lines += ["", f"Recording: {self.record_path}",
                      f"Trace (for opspec fit): {self.record_path.with_suffix('.trace.jsonl')}"
                      + (f" (person {self.person})" if self.person is not None else ""),
                      f"Replay it with: {walk}", f"           or: {run}"]
        return lines

    def close(self) -> None:
        if self._trace_file is not None:
            self._trace_file.close()
            self._trace_file = None


def clock(seconds: float) -> str:
    """``d1 08:00:00``: :func:`opspec.clock.clock_time` to the whole second (the walkthrough
    shows the clock ticking, not its milliseconds)."""
    return clock_time(math.floor(seconds))


def time_of_day_shown(seconds: float) -> str:
    """``08:00:00``: :func:`clock` without its day (for day 10 and later too)."""
    return clock(seconds).split(" ", 1)[1]