"""Real BPMN files from public modellers' example repositories and SpiffWorkflow's test data
(tests/bpmn/data/README.md says where each comes from): every one is either read and checked
or refused with located errors, never a traceback or a hang; those that run end on the path
SpiffWorkflow's own tests expect."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.cli import main
from opspec.engine.workitem import WorkItem
from opspec.errors import OpspecError, Severity
from opspec.xpdl.validate import validate_spec

DATA = Path(__file__).parent / "data"
FILES = sorted(p for p in DATA.iterdir() if p.suffix in (".bpmn", ".xml"))


def test_the_corpus_is_there() -> None:
    assert len(FILES) >= 20
    readme = (DATA / "README.md").read_text(encoding="utf-8")
    for path in FILES:
        assert path.name in readme, f"{path.name} has no source in README.md"


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_every_file_validates_or_is_refused_at_its_lines(
        path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    package, report = validate_spec(path)
    assert not any(d.code == "internal-error" for d in report.diagnostics), report.lines()
    for diagnostic in report.diagnostics:
        assert diagnostic.location.path == str(path)
        if diagnostic.severity is Severity.ERROR:
            assert diagnostic.location.line is not None, str(diagnostic)
    assert package is not None
    code = main(["validate", str(path)])
    out = capsys.readouterr()
    assert code == (0 if report.ok else 1)
    assert "Traceback" not in out.out + out.err


# Files with errors, and why: the reasons SpiffWorkflow (or BPMN) gives too.
REFUSED = {
    "spiff_standard_loop_invalid.bpmn": "standard-loop-without-end",   # ParseStandardLoop
    "spiff_Subprocess-Not-Found.bpmn20.xml": "missing-subflow-target",
    "spiff_call_activity_end_event.bpmn": "undefined-subflow",           # process in another file
    "spiff_ScriptTest.bpmn": "bad-script",                 # dicts, lists, def: not our grammar
    "camunda_loan-granting.bpmn": "multi-instance-without-count",  # camunda:collection
}

# How many of the files load, and how many of those run (a user completing every offer after
# 1 s: no run error, no aborted instance, a process completes). Before BPMN data was read
# (commit 576c6e5) 23 of these 38 loaded and 19 ran, 4 of them without running their scripts;
# before run inputs and undecided gateways (issue 28), 26 loaded and 20 ran; before call
# activities into other files (issue 28), 29 loaded and 22 ran.
LOADED, RAN = 30, 23


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_files_with_errors_are_refused_for_the_right_reason(name: str) -> None:
    _package, report = validate_spec(DATA / name)
    assert not report.ok
    assert REFUSED[name] in {d.code for d in report.diagnostics if d.severity is Severity.ERROR}


def test_spiff_call_activity_into_a_sibling_file_passes_data_both_ways() -> None:
    # SpiffWorkflow IOSpecTest (io_spec_parent.bpmn calls "subprocess" of io_spec.bpmn): the
    # called process is found in the file beside the caller; its ioSpecification takes in_1,
    # in_2 from the caller and hands out_1, out_2 back; "unused" stays the caller's
    outcome = opspec.run(DATA / "spiff_io_spec_parent.bpmn")
    parent: dict[str, object] = {}
    for event in outcome.trace:
        if event.kind == "data.changed" and event.process == "parent":
            parent.update(event.data)
    assert parent == {"in_1": 1, "in_2": "hello world", "unused": True, "out_1": 2,
                      "out_2": "HELLO WORLD"}


def _completed(outcome: opspec.RunOutcome, process: str) -> list[tuple[float, str]]:
    return [(e.time, e.activity or "") for e in outcome.trace
            if e.kind == "activity.completed" and e.process == process]


def test_spiff_timer_waits_its_duration_then_completes() -> None:
    # SpiffWorkflow TimerDurationTest: the intermediate timer "Take 5" ("PT0.25S") fires,
    # then the workflow completes
    outcome = opspec.run(DATA / "spiff_timer.bpmn")
    assert _completed(outcome, "timer") == [(0.0, "StartEvent_1"), (0.25, "Event_0bxivgz"),
                                            (0.25, "Event_03w65sk")]
    assert [e.kind for e in outcome.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]


def test_spiff_non_interrupting_boundary_timer_leaves_the_task_running() -> None:
    # SpiffWorkflow TimerDurationBoundaryOnTaskTest: the non-interrupting timer on the user
    # task fires (set_variable sets timer_called = True), the task can still be completed,
    # and the workflow then completes
    from opspec.testing import parse_script

    outcome = opspec.run(DATA / "spiff_boundary_timer_on_task.bpmn",
                         script=parse_script([(1.0, "complete user_task")]))
    done = _completed(outcome, "test_timer")
    assert done == [(0.0, "StartEvent_1"), (0.0, "Activity_0dzjjk3"), (0.002, "Event_0y4hbl0"),
                    (0.002, "set_variable"), (1.0, "user_task"), (1.0, "final_end_event")]
    deadline = next(e for e in outcome.trace if e.kind == "deadline.expired")
    assert (deadline.activity, deadline.data["synchronous"]) == ("user_task", False)
    changes = [(e.activity, dict(e.data)) for e in outcome.trace if e.kind == "data.changed"]
    assert changes == [("Activity_0dzjjk3", {"timer_called": False}),
                       ("set_variable", {"timer_called": True})]
    assert [e.kind for e in outcome.trace][-2:] == ["process.completed", "run.ended"]


def test_spiff_sequential_multi_instance_runs_three_instances() -> None:
    # SpiffWorkflow SequentialMultiInstanceTest: loopCardinality 3, one after the other
    outcome = opspec.run(DATA / "spiff_sequential_multiinstance_cardinality.bpmn")
    assert [a for _, a in _completed(outcome, "main")].count("any_task") == 3
    assert any(e.kind == "process.completed" for e in outcome.trace)


def test_spiff_parallel_multi_instance_runs_three_instances() -> None:
    outcome = opspec.run(DATA / "spiff_parallel_multiinstance_cardinality.bpmn")
    started = [e for e in outcome.trace if e.kind == "activity.started"
               and e.activity == "any_task"]
    assert len(started) == 3
    assert any(e.kind == "process.completed" for e in outcome.trace)


class _Patient:
    """Completes every offered item 1 s after the offer (the first alternative of a choice)."""

    def attach(self, session: object) -> None:
        self.session = session

    def offer(self, item: WorkItem) -> None:
        session = self.session
        session.call_later(1.0, lambda: session.complete(  # type: ignore[attr-defined]
            item, choice=item.choices[0] if item.choices else None))

    def withdraw(self, item: object, reason: str) -> None:
        pass


def test_how_many_files_load_and_run() -> None:
    loaded = ran = 0
    for path in FILES:
        package, report = validate_spec(path)
        if not report.ok or package is None:
            continue
        loaded += 1
        users = {p.id: _Patient() for p in package.participants} | {"user": _Patient()}
        try:
            outcome = opspec.run(path, performers=users, days=1)
        except OpspecError:
            continue
        kinds = [e.kind for e in outcome.trace]
        ran += "process.completed" in kinds and "process.aborted" not in kinds
    assert (len(FILES), loaded, ran) == (38, LOADED, RAN)
