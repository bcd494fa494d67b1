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

Each of these is a part of its own (a mixin over the state they share,
:mod:`~opspec.tui.session_state`): the clock and the pace of a call
(:mod:`~opspec.tui.session_clock`), the person's lane (:mod:`~opspec.tui.session_lane`), what
the trace says is running (:mod:`~opspec.tui.session_events`) and the recording
(:mod:`~opspec.tui.session_record`). This module builds the run and ends it.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.engine.compiled import K_GATEWAY, K_NOOP, CompiledPackage
from opspec.engine.lanes import all_activities, user_lane
from opspec.engine.trace import TraceEvent
from opspec.errors import ExecutionError
from opspec.run_rules import run_length
from opspec.tui.feedback import Aftermath
from opspec.tui.lane import LaneUser, Offer
from opspec.tui.session_clock import SessionClock, clock, time_of_day_shown
from opspec.tui.session_events import TraceFollower
from opspec.tui.session_lane import PersonLane
from opspec.tui.session_record import Recording
from opspec.tui.session_state import ON_CALL, guarded
from opspec.tui.summary import metric_lines, replay_commands, response_lines

if TYPE_CHECKING:
    from opspec.runs import RunOutcome

# clock and time_of_day_shown moved to session_clock: importable from here as before
__all__ = ["ON_CALL", "Offer", "WalkSession", "clock", "time_of_day_shown"]

DAY = 86_400.0


class WalkSession(SessionClock, PersonLane, TraceFollower, Recording):
    """One walkthrough (see the module docstring)."""

    def __init__(self, compiled: CompiledPackage, *, seed: int = 0, days: float | None = None,
                 until: float | None = None, record: str | Path | None = None,
                 model_factory: Callable[[], Any] | None = None,
                 performers: Mapping[str, Any] | None = None, config: Any = None,
                 replay: Any = None, spec_path: str = "",
                 device_participants: Mapping[str, Sequence[str]] | None = None,
                 wall_devices: bool = False, on_call: str = "realtime",
                 person: str | None = None) -> None:
        super().__init__(compiled, seed=seed, days=days, until=until,
                         model_factory=model_factory, replay=replay, spec_path=spec_path,
                         device_participants=device_participants, wall_devices=wall_devices,
                         on_call=on_call, person=person)
        self._open_record(record, seed, spec_path, person)
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
        self.sim = self.run.sim
        self._boot()

    @guarded()
    def _boot(self) -> None:
        self.sim.boot()
        self._follow_call()

    def _fail(self, error: ExecutionError) -> None:
        """The engine cannot go on: end the session and show why (as an engine fault)."""
        self.failure = error
        self.ended = True
        self.skipping = False
        at = error.sim_time if error.sim_time is not None else self.now
        self._on_event(TraceEvent(at, "fault", lane="device", package=self.compiled.id,
                                  data={"device": "engine", "fault": str(error),
                                        "message": str(error)}))

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
        what the bound devices said (in full), and where the recording is with the commands
        that replay it to the second shown.
        ``final``: the end of the session (the run's outcome is taken, once); else the
        numbers so far, with the run going on."""
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
                      *metric_lines(metrics, medians, self.compiled.package.metrics)]
        if self.has_user_lane and not self.replaying:
            lines += ["", "Your response times (wall clock, from the offer to your key):",
                      *response_lines(self.responses, recorded=self.record_path is not None)]
        if self.board.notes:
            # the device panel shows a note on one line, cut at the panel's edge: in full here
            lines += ["", "What the bound devices said:",
                      *(f"  {note}" for note in self.board.notes)]
        if self.record_path is not None:
            # the end to replay to: where the person quit (or, so far, where the session
            # stands: the numbers above are those of the run up to now), or a --days /
            # --until of its own
            stopped = not self.ended and self.failure is None
            end = self.now if stopped else None if (
                self.horizon == run_length(self.compiled)) else self.horizon
            # opspec fit reads the user lane's activities: a spec without one leaves it
            # nothing to fit ("no activity of lane 'user'")
            trace = "Trace (for opspec fit)" if self.has_user_lane else "Trace"
            lines += ["", f"Recording: {self.record_path}",
                      f"{trace}: {self.record_path.with_suffix('.trace.jsonl')}"
                      + (f" (person {self.person})" if self.person is not None else "")]
            if end is not None and end <= 0:
                # quit before the clock first moved: no run ends at 0 s (--until refuses
                # it), and a replay would have nothing of the session's to show
                lines.append("Nothing to replay: the session stopped before its clock moved."
                             if final else "Nothing to replay yet: the clock has not moved.")
                return lines
            walk, run = replay_commands(self.spec_path or "SPEC", self.record_path,
                                        until=end, seed=self.seed)
            lines += [f"Replay it with: {walk}", f"           or: {run}"]
            bound = sorted({p for ps in self.board.device_participants.values() for p in ps})
            if bound:
                # the replays bind nothing: what the devices did (their timing, a fault, an
                # answer that never came) is not what the spec's simulated devices do
                lines.append(f"Both replays simulate {', '.join(bound)}, performed here by a "
                             "bound device: their numbers may differ from this session's.")
        return lines
