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
"""

from __future__ import annotations

import json
import math
import os
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opspec.engine.compiled import CompiledPackage
from opspec.engine.lanes import user_lane
from opspec.engine.performers import PerformerSession, WorkItem
from opspec.engine.simulation import Simulation
from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError
from opspec.tui.devices import DeviceBoard
from opspec.tui.replay import tagged_action

__all__ = ["Offer", "WalkSession"]

DAY = 86_400.0
_ANSWERED = frozenset({"activity.completed", "activity.omitted", "activity.failed",
                       "activity.withdrawn", "activity.aborted", "deadline.expired"})


@dataclass(frozen=True, slots=True)
class Offer:
    """Something the person can do now: an activity, or one alternative of a choice."""

    item: WorkItem
    choice: str | None          # the alternative, for a deferred choice

    @property
    def label(self) -> str:
        return self.choice or self.item.label or self.item.activity

    @property
    def action(self) -> str:
        """The recorded action, naming the instance (``complete hear_alarm #6``): a replay
        acts on the same one of several identical offers."""
        if self.choice:
            return tagged_action("choose", self.choice, self.item.instance)
        return tagged_action("complete", self.item.activity, self.item.instance)


class _LaneUser:
    """The user lane's performer: holds offers for the person, or passes them to a model."""

    def __init__(self, session: WalkSession) -> None:
        self.walk = session
        self.items: dict[int, WorkItem] = {}
        self.engine: PerformerSession | None = None
        self.model: Any = None

    def attach(self, session: PerformerSession) -> None:
        self.engine = session

    def offer(self, item: WorkItem) -> None:
        if self.model is not None:
            self.model.offer(item)
            return
        self.items[item.key] = item
        self.walk._offered(item)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        self.items.pop(item.key, None)
        if self.model is not None:
            self.model.withdraw(item, reason)


class _RecordingSession:
    """The engine session a handed-over model sees: its actions are recorded like the
    person's, so a replay without the model gives the same trace."""

    def __init__(self, walk: WalkSession, engine: PerformerSession) -> None:
        self.walk = walk
        self.engine = engine

    @property
    def now(self) -> float:
        return self.engine.now

    def complete(self, item: WorkItem, data: Mapping[str, Any] | None = None,
                 choice: str | None = None) -> None:
        self.walk._record(tagged_action("choose", choice, item.instance) if choice
                          else tagged_action("complete", item.activity, item.instance),
                          by="model")
        self.engine.complete(item, data, choice)

    def omit(self, item: WorkItem, reason: str = "") -> None:
        self.walk._record(tagged_action("omit", item.activity, item.instance), by="model")
        self.engine.omit(item, reason)

    def fail(self, item: WorkItem, exception: str, message: str = "") -> None:
        self.walk._record(tagged_action("fail", item.activity, item.instance, exception),
                          by="model")
        self.engine.fail(item, exception, message)

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        self.walk._record(f"raise {name}", by="model")
        self.engine.raise_trigger(name, data)

    def call_later(self, delay: float, callback: Callable[[], None]) -> None:
        self.engine.call_later(delay, callback)

    def trace(self, kind: str, data: Mapping[str, Any] | None = None) -> None:
        self.engine.trace(kind, data)


class WalkSession:
    """One walkthrough (see the module docstring)."""

    def __init__(self, compiled: CompiledPackage, *, seed: int = 0, days: float | None = None,
                 record: str | Path | None = None, model_factory: Callable[[], Any] | None = None,
                 performers: Mapping[str, Any] | None = None, config: Any = None,
                 replay: Any = None, spec_path: str = "",
                 device_participants: Mapping[str, Sequence[str]] | None = None,
                 wall_devices: bool = False) -> None:
        self.compiled = compiled
        self.seed = seed
        if days is not None and not (days > 0 and math.isfinite(days)):
            raise ConfigurationError(f"--days must be a positive number, not {days:g}",
                                     hint="e.g. --days 1 (or leave it out for the spec's "
                                     "opspec:RunLength)")
        #: where the run ends: ``days``, else the spec's opspec:RunLength (as ``opspec run``
        #: does), else one day
        self.horizon = (days * DAY if days is not None
                        else float(compiled.package.run_length)
                        if compiled.package.run_length is not None else DAY)
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
        self.offers: list[Offer] = []
        self.calling = False                                # the device is calling the user
        self.ended = False
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
        self._deadline_of = {(a.process, a.id): a.deadlines for a in _activities(compiled)
                             if a.deadlines}
        lane = user_lane(compiled)
        #: the spec has manual activities for the person (vacuum robots may have none)
        self.has_user_lane = not lane.empty
        self.lane_user = _LaneUser(self)
        bound: dict[str, Any] = dict(performers or {})
        if replay is not None:
            user: Any = replay
        else:
            user = self.lane_user
        for name in lane.bind_names:
            bound[name] = user
        listeners: list[Any] = [self.board, self._on_event]
        if replay is not None:
            listeners.append(replay)
        if self._trace_file is not None:
            listeners.append(self._trace_file)
        self.sim = Simulation(compiled, config, performers=bound, seed=seed, scope=(0,),
                              listeners=listeners)
        self.sim.boot()

    # ------------------------------------------------------------------ time
    @property
    def now(self) -> float:
        return float(self.sim.env.now)

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
            self._run_to(self.now, budget)
            return
        self._run_to(min(self.horizon, self.now + wall_seconds * self.speed), budget)

    @property
    def waiting_for_devices(self) -> bool:
        """Whether a real device (answering in wall time) has work it has not answered yet:
        skipping simulated time now would jump past its answer."""
        return self.wall_devices and bool(self.device_work)

    def skip_to_next_event(self, budget: int | None = None) -> None:
        """Jump to the next scheduled event (not while a real device is busy)."""
        if self.waiting_for_devices:
            return
        due = self.sim.peek()
        self._run_to(min(self.horizon, due if math.isfinite(due) else self.horizon), budget)

    def skip_until_user(self, budget: int | None = None) -> None:
        """Run until something is offered to the person (or the run ends). With a real
        device busy the skip pauses until it answers. With a ``budget`` (engine events per
        call) the skip may stop early with :attr:`skipping` still set: :meth:`advance` goes
        on with it, and :meth:`cancel_skip` abandons it."""
        self.skipping = True
        self._skip_calls = self.calls
        self._skip(budget)

    def cancel_skip(self) -> None:
        """Stop a skip in progress where it is."""
        self.skipping = False

    def _skip(self, budget: int | None = None) -> None:
        # with the lane handed over nothing waits for the person: stop at the next call
        calls = self._skip_calls
        left = budget
        while not self.offers and not self.ended and not self.waiting_for_devices and not (
                self.handed_over and self.calls > calls):
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
        if self.offers or self.ended or (self.handed_over and self.calls > calls):
            self.skipping = False

    def run_to(self, target: float, budget: int | None = None) -> bool:
        """Step the engine to simulated time ``target`` (at most ``budget`` events; it
        stops early at a new offer); ``False`` when the budget ran out first (the clock then
        stands at the last event stepped, and a later call goes on)."""
        return self._step_to(min(self.horizon, target), budget)[0]

    _run_to = run_to

    def _step_to(self, target: float, budget: int | None) -> tuple[bool, int]:
        env = self.sim.env
        self.sim.drain_posts()
        steps = 0
        while not self.offers or target > self.now:
            due = env.peek()
            if due > target:
                break
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
    def act(self, offer: Offer) -> None:
        """The person does ``offer`` now."""
        engine = self.lane_user.engine
        if engine is None or offer.item.key not in self.lane_user.items:
            return
        self.lane_user.items.pop(offer.item.key, None)
        self._record(offer.action, by="person")
        self._drop_offers(offer.item.key)
        engine.complete(offer.item, None, offer.choice)

    def ignore(self, offer: Offer) -> None:
        """The person explicitly does not do ``offer`` (omission)."""
        engine = self.lane_user.engine
        if engine is None or offer.item.key not in self.lane_user.items:
            return
        self.lane_user.items.pop(offer.item.key, None)
        self._record(tagged_action("omit", offer.item.activity, offer.item.instance),
                     by="person")
        self._drop_offers(offer.item.key)
        engine.omit(offer.item, "the person chose not to")

    def hand_over(self) -> bool:
        """Let the user model perform the lane from now on (``False``: no model)."""
        if self.model_factory is None or self.lane_user.model is not None:
            return False
        engine = self.lane_user.engine
        model = self.model_factory()
        if engine is not None:
            model.attach(_RecordingSession(self, engine))
        self.lane_user.model = model
        pending = list(self.lane_user.items.values())
        self.lane_user.items.clear()
        self.offers.clear()
        for item in pending:
            model.offer(item)
        return True

    def take_back(self) -> None:
        """The person performs the lane again (the model's pending work is withdrawn)."""
        self.lane_user.model = None

    @property
    def handed_over(self) -> bool:
        return self.lane_user.model is not None

    # ------------------------------------------------------------------ engine side
    def _offered(self, item: WorkItem) -> None:
        if item.choices:
            self.offers.extend(Offer(item, choice) for choice in item.choices)
        else:
            self.offers.append(Offer(item, None))

    def _drop_offers(self, key: int) -> None:
        self.offers = [o for o in self.offers if o.item.key != key]

    def _on_event(self, event: TraceEvent) -> None:
        self.events.append(event)
        kind = event.kind
        if kind == "activity.withdrawn" and event.activity:
            self.offers = [o for o in self.offers if not (
                o.item.instance == event.instance and o.item.activity == event.activity)]
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
            self.calling = True
            self.calls += 1
        if kind == "process.completed" and event.lane == "user":
            self.calling = False
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


def _activities(compiled: CompiledPackage) -> list[Any]:
    from opspec.engine.lanes import all_activities

    return list(all_activities(compiled))
