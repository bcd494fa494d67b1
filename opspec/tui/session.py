"""A walkthrough session without any UI: the engine, the person's lane, the clock, the record.

The Textual app (:mod:`opspec.tui.app`) is a view of this object and sends it the person's
actions; tests drive it directly too. Everything here runs on the caller's thread (the app's
event loop): SimPy is stepped, never run from another thread.

- **Time**: :meth:`advance` moves simulated time by ``wall_seconds × speed`` (nothing happens
  while paused); :meth:`skip_to_next_event` jumps to the next scheduled event;
  :meth:`skip_until_user` runs until something is offered to the person (or the run ends).
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
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

from opspec.engine.compiled import CompiledPackage
from opspec.engine.lanes import all_activities, user_lane
from opspec.engine.performers import WorkItem
from opspec.engine.simulation import Simulation
from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError, ExecutionError
from opspec.tui.devices import DeviceBoard
from opspec.tui.lane import LaneUser, Offer
from opspec.tui.replay import tagged_action

__all__ = ["Offer", "WalkSession"]

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
                 wall_devices: bool = False) -> None:
        from opspec.runs import check_seed, run_length

        self.compiled = compiled
        self.seed = check_seed(seed)
        if days is not None and not (days > 0 and math.isfinite(days)):
            raise ConfigurationError(f"--days must be a positive number, not {days:g}",
                                     hint="e.g. --days 1 (or leave it out for the spec's "
                                     "opspec:RunLength)")
        #: where the run ends: the one rule of every run (opspec.runs.run_length): ``days``,
        #: else the spec's opspec:RunLength, else one day
        self.horizon = run_length(compiled, days=days)
        self.speed = 60.0
        self.paused = False
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
        #: the error that ended the run (a zero-time cycle...), or None
        self.failure: ExecutionError | None = None
        self.record_path = Path(record) if record is not None else None
        self._steps: list[list[str]] = []
        self._trace_file = None
        if self.record_path is not None:
            trace_path = self.record_path.with_suffix(".trace.jsonl")
            try:
                self.record_path.parent.mkdir(parents=True, exist_ok=True)
                self._write_record()
                from opspec.engine.trace_sinks import JsonlSink

                self._trace_file = JsonlSink(trace_path, {"spec": spec_path, "seed": seed,
                                                          "walkthrough": True}, flush_every=1)
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
        """Jump to the next scheduled event (not while a real device is busy)."""
        if self.waiting_for_devices:
            return
        due = self.sim.peek()
        self.run_to(min(self.horizon, due if math.isfinite(due) else self.horizon), budget)

    @_guarded()
    def skip_until_user(self, budget: int | None = None) -> None:
        """Run until something is offered to the person (or the run ends). With a real
        device busy the skip pauses until it answers. With a ``budget`` (engine events per
        call) the skip may stop early with :attr:`skipping` still set: :meth:`advance` goes
        on with it, and :meth:`cancel_skip` abandons it."""
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
        """Step the engine to simulated time ``target`` (at most ``budget`` events; it
        stops early at a new offer); ``False`` when the budget ran out first (the clock then
        stands at the last event stepped, and a later call goes on)."""
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
        if target > env.now:
            env.run(until=target)
        if self.now >= self.horizon - 1e-9 and not self.ended:
            self.ended = True
            self.sim.check_waiting(horizon=self.horizon)
        return True, steps

    # ------------------------------------------------------------------ the person
    @_guarded()
    def act(self, offer: Offer) -> None:
        """The person does ``offer`` now."""
        engine = self.lane_user.engine
        if engine is None or self.ended or self.handed_over or (
                offer.item.key not in self.lane_user.items):
            return
        self.lane_user.items.pop(offer.item.key, None)
        self._record(offer.action, by="person")
        self._drop_offers(offer.item.key)
        engine.complete(offer.item, None, offer.choice)

    @_guarded()
    def ignore(self, offer: Offer) -> None:
        """The person explicitly does not do ``offer`` (omission)."""
        engine = self.lane_user.engine
        if engine is None or self.ended or self.handed_over or (
                offer.item.key not in self.lane_user.items):
            return
        self.lane_user.items.pop(offer.item.key, None)
        self._record(tagged_action("omit", offer.item.activity, offer.item.instance),
                     by="person")
        self._drop_offers(offer.item.key)
        engine.omit(offer.item, "the person chose not to")

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
            for key in stale:
                self.lane_user.items.pop(key, None)
            self._drop_offers(*stale)
        self._offer_seq += 1
        self._seq_of[item.key] = self._offer_seq
        if item.choices:
            self.offers.extend(Offer(item, choice, self._names.get((item.process, choice)))
                               for choice in item.choices)
        else:
            self.offers.append(Offer(item, None))

    def _drop_offers(self, *keys: int) -> None:
        self.offers = [o for o in self.offers if o.item.key not in keys]
        for key in keys:
            self._seq_of.pop(key, None)

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
        if event.instance is not None and event.activity:
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
                f"{event.activity} at {clock(event.time)[3:]}")
        if kind in ("fault", "device.note"):
            data = event.data or {}
            who = str(data.get("participant") or data.get("device") or "device")
            prefix = "FAULT: " if kind == "fault" else "note: "
            self.participants[who] = prefix + str(data.get("message", ""))
        if kind == "process.started" and event.lane == "user":
            self.calls += 1
        for listener in self.listeners:
            listener(event)

    # ------------------------------------------------------------------ recording
    def _record(self, action: str, *, by: str) -> None:
        self._steps.append([f"at {self.now!r}", action])
        self._write_record()
        self.sim.session.trace("walkthrough.action", {
            "action": action, "by": by, "wall": time.time()})  # wall-clock: the record

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

    def close(self) -> None:
        if self._trace_file is not None:
            self._trace_file.close()
            self._trace_file = None


def clock(seconds: float) -> str:
    day, rest = divmod(seconds, DAY)
    hours, rest = divmod(rest, 3600)
    minutes, secs = divmod(rest, 60)
    return f"d{int(day) + 1} {int(hours):02d}:{int(minutes):02d}:{int(secs):02d}"

