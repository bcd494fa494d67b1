"""Run BPMN files through SpiffWorkflow (the maintained Python BPMN engine) on a virtual clock
and print, for each, the flow nodes it completed and how the run ended, as JSON.

Run inside the test-only venv (scripts/spiff-venv.sh), never inside opspec's:

    .spiff-venv/bin/python tests/differential/spiff_driver.py A.bpmn B.bpmn ...
    echo '[{"file": "A.bpmn", "data": {"x": null}, "delay": 3600, "parser": "camunda"}]' \
        | .spiff-venv/bin/python tests/differential/spiff_driver.py

One process runs every file (the test pays the interpreter's start once). For each run it
prints one JSON line: ``{"file": path, "delay": seconds, "loaded": bool, "error": str|null, "state":
"completed"|"waiting"|"error"|"hang", "completed": [flow node ids in completion order],
"processes": [process ids run], "clock": seconds of virtual time used}``.

How a file is run, the same way opspec's side of tests/differential/test_spiff.py runs it:

- the parser: ``parser`` of the entry (``bpmn``, ``camunda``, ``spiff``: the one SpiffWorkflow's
  tests of that folder use);
- the processes to run: every process that no call activity of the file calls (of a
  collaboration's pools, the executable ones, as SpiffWorkflow's ``get_collaboration`` starts
  them), all in one workflow, so that messages flow between them; a process that a call
  activity calls runs as that call only, as in SpiffWorkflow's own tests of these files;
- the initial data given with the file (the test gives the data fields opspec reads from the
  file, with their initial values, null when they have none: form field defaults, data
  objects; SpiffWorkflow's own parser reads no Camunda form), else none;
- every ready user or manual task is completed ``delay`` seconds (given with the file; 0 by
  default) after it became ready, a plain ``task`` (which SpiffWorkflow leaves to a person, and
  opspec runs by itself) at once; one at a time, in the order they are due, then in the order
  they became ready, without data (SpiffWorkflow's ``task.run()``); a service task without an
  implementation, which SpiffWorkflow leaves waiting for the application, is answered at once;
- script tasks run in SpiffWorkflow's Python script engine, with the two helpers its own timer
  tests register; a service it calls answers at once (``script_engine``);
- timers: the clock is virtual (``datetime.now`` of SpiffWorkflow's timer module is replaced),
  it starts at 2026-01-01T00:00:00Z and jumps to the next timer's moment whenever nothing else
  can move, never sleeping, up to ``HORIZON`` seconds.
"""

from __future__ import annotations

import contextlib
import json
import signal
import sys
from datetime import datetime, timedelta, timezone

HORIZON = 86_400.0       # one day of virtual time, as opspec's default run length
MAX_STEPS = 2_000        # rounds of user-task completions and clock jumps per file
MAX_COMPLETIONS = 120    # flow-node completions per file before it counts as a livelock
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


def script_engine():
    """SpiffWorkflow's Python script engine with the helpers its own timer tests register
    (``custom_function``, a call counter, and ``timedelta``), so that their scripts run as in
    SpiffWorkflow's suite (opspec skips the output statements that call them), and a service
    that answers every call at once with an empty JSON object (opspec runs a service task as
    completing by itself)."""
    from SpiffWorkflow.bpmn.script_engine import PythonScriptEngine, TaskDataEnvironment

    calls = [0]

    def custom_function():
        calls[0] += 1
        return calls[0]

    class Environment(TaskDataEnvironment):
        def call_service(self, context, **kwargs):
            return "{}"

    return PythonScriptEngine(environment=Environment(
        {"custom_function": custom_function, "timedelta": timedelta}))


def parser_for(kind: str):
    """The parser SpiffWorkflow's own tests read the file with: the plain BPMN parser for its
    ``bpmn`` tests, the Camunda or the Spiff-extensions parser for those folders."""
    if kind == "camunda":
        from SpiffWorkflow.camunda.parser.CamundaParser import CamundaParser
        return CamundaParser()
    if kind == "spiff":
        from SpiffWorkflow.spiff.parser.process import SpiffBpmnParser
        return SpiffBpmnParser()
    from SpiffWorkflow.bpmn.parser import BpmnParser
    return BpmnParser()


def workflows_of(path: str, kind: str = "bpmn"):
    """The processes a run of the file starts and the one workflow that runs them (see the
    module docstring)."""
    from SpiffWorkflow.bpmn.parser.util import full_tag
    from SpiffWorkflow.bpmn.specs.bpmn_process_spec import BpmnProcessSpec
    from SpiffWorkflow.bpmn.workflow import BpmnWorkflow

    parser = parser_for(kind)
    parser.add_bpmn_file(path)
    ids = list(parser.process_parsers)    # get_process_ids() leaves out non-executable ones
    called: set[str] = set()
    for process_id in ids:
        parsed = parser.get_process_parser(process_id)
        if parsed.process_executable:
            called |= set(parser.get_subprocess_specs(process_id,
                                                      require_call_activity_specs=False))
    roots = [pid for pid in ids if pid not in called]
    if parser.collaborations:
        # the pools of a collaboration: SpiffWorkflow starts the executable ones
        pools = {p for members in parser.collaborations.values() for p in members}
        roots = [pid for pid in roots
                 if pid not in pools or parser.get_process_parser(pid).process_executable]
    if not roots:
        raise ValueError("no process to start: every process is called by a call activity")
    if len(roots) == 1:
        return roots, BpmnWorkflow(parser.get_spec(roots[0]),
                                   parser.get_subprocess_specs(roots[0]),
                                   script_engine=script_engine())
    # several processes start together, as SpiffWorkflow's get_collaboration starts the pools
    # of a collaboration: one workflow, so that messages flow between them
    spec = BpmnProcessSpec("differential")
    subprocesses = {}
    participant = parser._get_parser_class(full_tag("callActivity"))[1]
    for pid in roots:
        subprocesses[pid] = parser.get_spec(pid)
        subprocesses.update(parser.get_subprocess_specs(pid))
        spec.start.connect_or_add_trigger(participant(spec, pid, pid), subprocesses[pid])
    return roots, BpmnWorkflow(spec, subprocesses, script_engine=script_engine())


def next_timer(workflow) -> datetime | None:
    """The earliest moment a waiting timer fires: SpiffWorkflow keeps it in the waiting task's
    ``event_value`` (an ISO date-time, or a cycle's ``next``), also for the timers of an
    event-based gateway, whose pending event carries no value."""
    moments = []
    for task in list(workflow.event_manager.tasks.values()):
        value = task.internal_data.get("event_value")
        if isinstance(value, dict):
            value = value.get("next") if value.get("cycles") != 0 else None
        if not isinstance(value, str):
            continue
        try:
            moment = datetime.fromisoformat(value)
        except ValueError:
            continue
        moments.append(moment if moment.tzinfo else moment.replace(tzinfo=timezone.utc))
    return min(moments) if moments else None


def run_workflow(workflow, delay: float) -> str:
    from SpiffWorkflow.bpmn.specs.mixins.manual_task import ManualTask
    from SpiffWorkflow.bpmn.specs.mixins.service_task import ServiceTask
    from SpiffWorkflow.bpmn.specs.mixins.user_task import UserTask
    from SpiffWorkflow.util.task import TaskState

    due: dict = {}          # task id -> (when the performer completes it, order offered)
    for _ in range(MAX_STEPS):
        workflow.do_engine_steps()
        workflow.refresh_timers()
        workflow.do_engine_steps()
        if workflow.get_tasks(state=TaskState.ERROR):
            return "error"
        ready = workflow.get_tasks(state=TaskState.READY, manual=True)
        for task in ready:
            # a person takes ``delay`` for a user or manual task; a plain task, which
            # SpiffWorkflow also leaves to someone, runs by itself in opspec: at once
            person = isinstance(task.task_spec, (UserTask, ManualTask))
            due.setdefault(task.id, (Clock.now + timedelta(seconds=delay if person else 0),
                                     len(due)))
        # first due, first served; at one moment in the order offered (opspec's performer
        # is called back in that order too)
        ready = sorted((t for t in ready if due[t.id][0] <= Clock.now), key=lambda t: due[t.id])
        # a service task without an implementation waits (STARTED) for the application to
        # answer; the application answers at once, as opspec runs such a task
        waiting_services = [t for t in workflow.get_tasks(state=TaskState.STARTED)
                            if isinstance(t.task_spec, ServiceTask)]
        if ready:
            # one at a time, each followed by what it causes (opspec's performer is served in
            # the same way): completing every ready task before the engine moves would let
            # a task finish that the first one's terminate end event cancels
            ready[0].run()
            continue
        if waiting_services:
            for task in waiting_services:
                if task.state == TaskState.STARTED:
                    task.complete()
            continue
        if workflow.is_completed():
            return "completed"
        pending = [due[t.id][0] for t in workflow.get_tasks(state=TaskState.READY, manual=True)]
        timer = next_timer(workflow)
        moment = min([*pending, *([timer + timedelta(microseconds=1)] if timer else [])],
                     default=None)
        if moment is None or moment >= EPOCH + timedelta(seconds=HORIZON):
            return "waiting"
        # SpiffWorkflow fires a timer when its moment is strictly before now (hence 1 us)
        Clock.now = max(Clock.now, moment)
    return "waiting"


def run_file(path: str, data: dict, delay: float, kind: str = "bpmn") -> dict:
    completed: list[str] = []
    result = {"file": path, "delay": delay, "loaded": False, "error": None, "state": "error",
              "completed": completed, "processes": [], "clock": 0.0}
    Clock.now = EPOCH
    record_completions(completed)
    try:
        signal.alarm(WALL_LIMIT)
        try:
            processes, workflow = workflows_of(path, kind)
            for task in workflow.get_tasks(spec_name="Start"):
                task.data.update(data)
            result["processes"] = processes
            result["loaded"] = True
            result["state"] = run_workflow(workflow, delay)
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
    runs = ([{"file": path} for path in sys.argv[1:]] if len(sys.argv) > 1
            else json.load(sys.stdin))
    for one in runs:
        Task._set_state = pristine
        # what the files' scripts print goes to stderr: stdout carries the JSON lines only
        with contextlib.redirect_stdout(sys.stderr):
            result = run_file(one["file"], one.get("data") or {}, one.get("delay", 0.0),
                              one.get("parser", "bpmn"))
        print(json.dumps(result), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
