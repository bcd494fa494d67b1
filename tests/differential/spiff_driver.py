"""Run BPMN files through SpiffWorkflow (the maintained Python BPMN engine) on a virtual clock
and print, for each, the flow nodes it completed and how the run ended, as JSON.

Run inside the test-only venv (scripts/spiff-venv.sh), never inside opspec's:

    .spiff-venv/bin/python tests/differential/spiff_driver.py A.bpmn B.bpmn ...

One process runs every file (the test pays the interpreter's start once). For each file it
prints one JSON line: ``{"file": path, "loaded": bool, "error": str|null, "state":
"completed"|"waiting"|"error"|"hang", "completed": [flow node ids in completion order],
"processes": [process ids run], "clock": seconds of virtual time used}``.

How a file is run, the same way opspec's side of tests/differential/test_spiff.py runs it:

- the process to run: the file's collaboration (every executable participant, as SpiffWorkflow's
  ``get_collaboration`` starts them) when it has one, else every executable process that no call
  activity of the file calls, each in its own workflow;
- no initial data: the workflow's data is what the file itself sets;
- every ready user or manual task (and plain ``task``, which SpiffWorkflow leaves to a person)
  is completed at once, in the engine's task order, without data (SpiffWorkflow's
  ``task.run()``); a service task without an implementation, which SpiffWorkflow leaves
  waiting for the application, is answered at once;
- script tasks run in SpiffWorkflow's Python script engine;
- timers: the clock is virtual (``datetime.now`` of SpiffWorkflow's timer module is replaced),
  it starts at 2026-01-01T00:00:00Z and jumps to the next timer's moment whenever nothing else
  can move, never sleeping, up to ``HORIZON`` seconds.
"""

from __future__ import annotations

import json
import signal
import sys
from datetime import datetime, timedelta, timezone

HORIZON = 86_400.0       # one day of virtual time, as opspec's default run length
MAX_STEPS = 2_000        # rounds of user-task completions and clock jumps per file
MAX_COMPLETIONS = 2_000  # flow-node completions per file before it counts as a livelock
WALL_LIMIT = 10          # seconds of real time per file before it counts as a hang
EPOCH = datetime(2026, 1, 1, tzinfo=timezone.utc)


class Clock:
    now = EPOCH


class VirtualDatetime(datetime):
    """``datetime`` whose ``now`` is the virtual clock (SpiffWorkflow's timers call it)."""

    @classmethod
    def now(cls, tz=None):  # noqa: D102
        moment = Clock.now
        return moment.astimezone(tz) if tz is not None else moment.replace(tzinfo=None)


class Hang(BaseException):
    """The run does not end: more than ``MAX_COMPLETIONS`` completions, or ``WALL_LIMIT``.
    A BaseException, so that SpiffWorkflow's own ``except Exception`` does not wrap it."""


def _alarm(signum, frame):
    raise Hang(f"still running after {WALL_LIMIT} s of real time")


def install_clock() -> None:
    from SpiffWorkflow.bpmn.specs.event_definitions import timer

    timer.datetime = VirtualDatetime


def record_completions(completed: list[str]) -> None:
    """Every task that becomes COMPLETED and stands for a flow node of the file (SpiffWorkflow's
    own bookkeeping tasks, Start, End, boundary splits, have no ``bpmn_id``) is appended. A
    loop or multi-instance activity counts once per iteration or instance (its inner task), as
    opspec's trace counts it, not once more for SpiffWorkflow's task that holds them."""
    from SpiffWorkflow.bpmn.specs.mixins.multiinstance_task import LoopTask
    from SpiffWorkflow.task import Task
    from SpiffWorkflow.util.task import TaskState

    original = Task._set_state

    def _set_state(task, value):
        before = task.state
        original(task, value)
        if value == TaskState.COMPLETED and before != TaskState.COMPLETED:
            bpmn_id = getattr(task.task_spec, "bpmn_id", None)
            if bpmn_id is not None and not isinstance(task.task_spec, LoopTask):
                completed.append(bpmn_id)
                if len(completed) > MAX_COMPLETIONS:
                    raise Hang(f"more than {MAX_COMPLETIONS} flow-node completions")

    Task._set_state = _set_state


def workflows_of(path: str):
    """The workflows a run of the file starts (see the module docstring)."""
    from SpiffWorkflow.bpmn.parser import BpmnParser
    from SpiffWorkflow.bpmn.workflow import BpmnWorkflow

    parser = BpmnParser()
    parser.add_bpmn_file(path)
    if parser.collaborations:
        name = sorted(parser.collaborations)[0]
        spec, subprocesses = parser.get_collaboration(name)
        return [name], [BpmnWorkflow(spec, subprocesses)]
    # a process that a call activity of the file calls runs as that call, not on its own
    specs = parser.find_all_specs()
    called = set()
    for process_id in specs:
        called |= set(parser.get_subprocess_specs(process_id, require_call_activity_specs=False))
    roots = [pid for pid in parser.get_process_ids()
             if pid not in called and parser.get_process_parser(pid).process_executable]
    return roots, [BpmnWorkflow(parser.get_spec(pid), parser.get_subprocess_specs(pid))
                   for pid in roots]


def next_timer(workflow) -> datetime | None:
    moments = []
    for event in workflow.waiting_events():
        value = event.value
        if isinstance(value, str):
            try:
                moment = datetime.fromisoformat(value)
            except ValueError:
                continue
            if moment.tzinfo is None:
                moment = moment.replace(tzinfo=timezone.utc)
            moments.append(moment)
    return min(moments) if moments else None


def run_workflow(workflow) -> str:
    from SpiffWorkflow.bpmn.specs.mixins.service_task import ServiceTask
    from SpiffWorkflow.util.task import TaskState

    for _ in range(MAX_STEPS):
        workflow.do_engine_steps()
        workflow.refresh_timers()
        workflow.do_engine_steps()
        if workflow.get_tasks(state=TaskState.ERROR):
            return "error"
        ready = workflow.get_tasks(state=TaskState.READY, manual=True)
        # a service task without an implementation waits (STARTED) for the application to
        # answer; the application answers at once, as opspec runs such a task
        waiting_services = [t for t in workflow.get_tasks(state=TaskState.STARTED)
                            if isinstance(t.task_spec, ServiceTask)]
        if ready or waiting_services:
            for task in ready:
                if task.state == TaskState.READY:
                    task.run()
            for task in waiting_services:
                if task.state == TaskState.STARTED:
                    task.complete()
            continue
        if workflow.is_completed():
            return "completed"
        moment = next_timer(workflow)
        if moment is None or moment >= EPOCH + timedelta(seconds=HORIZON):
            return "waiting"
        # SpiffWorkflow fires a timer when its moment is strictly before now
        Clock.now = max(Clock.now, moment) + timedelta(microseconds=1)
    return "waiting"


def run_file(path: str) -> dict:
    completed: list[str] = []
    result = {"file": path, "loaded": False, "error": None, "state": "error",
              "completed": completed, "processes": [], "clock": 0.0}
    Clock.now = EPOCH
    record_completions(completed)
    try:
        signal.alarm(WALL_LIMIT)
        try:
            processes, workflows = workflows_of(path)
            result["processes"] = processes
            result["loaded"] = True
            states = [run_workflow(workflow) for workflow in workflows]
            if not states:
                result["error"] = "no executable process that no call activity calls"
            result["state"] = ("error" if not states or "error" in states else "completed"
                               if all(s == "completed" for s in states) else "waiting")
        finally:
            signal.alarm(0)
    except Hang as exc:
        result["state"], result["error"] = "hang", str(exc)
    except Exception as exc:  # the engine's own failure is the fact we report
        result["error"] = f"{type(exc).__name__}: {exc}".splitlines()[0][:300]
    result["clock"] = (Clock.now - EPOCH).total_seconds()
    return result


def main() -> int:
    import logging
    import warnings

    logging.disable(logging.CRITICAL)
    warnings.simplefilter("ignore")
    signal.signal(signal.SIGALRM, _alarm)
    install_clock()
    from SpiffWorkflow.task import Task
    pristine = Task._set_state
    for path in sys.argv[1:]:
        Task._set_state = pristine
        print(json.dumps(run_file(path)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
