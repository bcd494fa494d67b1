"""The recording of a walkthrough session: every action (the person's, or the model's while
the lane is handed over) written at once to the recording, a script ``opspec run --script``
replays, and every trace event to ``<recording>.trace.jsonl`` with how long the person took
(for ``opspec fit``). The trace also keeps where the session ended, which the script cannot
hold: the run's end in its header (``until``), and a ``walkthrough.quit`` event where the
person quit before it, so that a replay ends there too (:func:`opspec.tui.replay.recorded_end`).
Every session's trace ends as ``opspec run``'s does, with ``run.ended``
(:meth:`Recording._trace_run_ended`): at the end of the run, or after the ``walkthrough.quit``
of a session quit before it (by ``q``, Ctrl+C or an interrupt) and the deadlocks the end of a
run would report there (:meth:`Recording._judge_waiting`); then what
is traced when the session closes (:meth:`Recording.before_close`: the bound devices'
unfinished work, ``device.pending``, which ``opspec run`` also traces after ``run.ended``),
whoever closes it. A run that failed has no ``run.ended``, as in ``opspec run``."""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from opspec.engine.performers import WorkItem
from opspec.engine.trace import EventKind
from opspec.errors import ConfigurationError
from opspec.tui.replay import QUIT
from opspec.tui.session_state import SessionState, guarded

__all__ = ["Recording"]


class Recording(SessionState):
    """The recording of a :class:`~opspec.tui.session.WalkSession`."""

    def _open_record(self, record: str | Path | None, seed: int, spec_path: str,
                     person: str | None) -> None:
        """Start the recording (``None``: none) and its trace file, both written as the
        session goes on."""
        self.record_path = Path(record) if record is not None else None
        self._steps = []
        self._trace_file = None
        self._closing = []
        self._quit = False               # the person quit before the end of the run
        if self.record_path is not None:
            trace_path = self.record_path.with_suffix(".trace.jsonl")
            try:
                self.record_path.parent.mkdir(parents=True, exist_ok=True)
                self._write_record()
                from opspec.engine.trace_sinks import JsonlSink

                # where the run is to end: a replay of the recording ends there too
                header: dict[str, Any] = {"spec": spec_path, "seed": seed, "walkthrough": True,
                                          "until": self.horizon}
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
                # x is recorded as "omit hear_alarm #6" and labelled "not: Hear the alarm"
                omitted = action.split(" ", 1)[0] == "omit"
                self.responses.append(response.named(
                    (label.removeprefix("not: ") if omitted else label) or item.activity,
                    self.now, omitted=omitted))
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

    def before_close(self, hook: Callable[[], object]) -> None:
        """Call ``hook`` when the session closes, while its trace is still open: the app
        closes the session when the person quits, before ``opspec walkthrough`` gets back
        control, so what the command traces at the end (``device.pending``) would otherwise
        reach a closed trace."""
        self._closing.append(hook)

    def _trace_run_ended(self) -> None:
        """Trace ``run.ended`` (``open`` instances, ``deadlocks``), as ``opspec run`` does when
        its run returns: a stored trace's readers take the run's end from it
        (:func:`opspec.properties.evaluator.trace_end`; without it, the last event's time,
        and what was still pending at the end would be judged too early)."""
        sim = self.sim
        sim.session.trace(EventKind.RUN_ENDED, {"open": len(sim.live),
                                                "deadlocks": len(sim.deadlocks)})

    @guarded()
    def _judge_waiting(self) -> None:
        """What can never go on, judged where the person quit as at the end of a run that
        stopped at its horizon (:meth:`~opspec.engine.simulation.Simulation.check_waiting`,
        as ``opspec run --until`` the quit second does): an activity waiting for a performer
        that does not exist is a deadlock; what waits for the person, or for a device, is
        not (they could still have answered). With nothing scheduled at all (a session quit
        before its clock first moved) ``check_waiting`` would take every instance waiting
        for the person as deadlocked: nothing is judged then."""
        if math.isfinite(self.sim.peek()):
            self.sim.check_waiting(horizon=self.now)

    def close(self) -> None:
        hooks, self._closing = self._closing, []        # once, however often it is closed
        try:
            try:
                if not self.ended and self.failure is None and not self._quit:
                    self._quit = True
                    if self._trace_file is not None:
                        # the person quit here: a replay of the recording ends here too
                        # (opspec.tui.replay.recorded_end), and so does the run
                        self.sim.session.trace(QUIT, {"until": self.now})
                    # (also unrecorded: the summary's numbers are those of opspec run)
                    self._judge_waiting()
                    if self._trace_file is not None and self.failure is None:
                        self._trace_run_ended()
            finally:
                for hook in hooks:          # after run.ended, as in opspec run's trace
                    hook()
        finally:
            if self._trace_file is not None:
                self._trace_file.close()
                self._trace_file = None
