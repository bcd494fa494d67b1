"""A session quit before the end of its run says, before its ``run.ended``, what can never go
on, as the end of a run does (`opspec run`'s, and a walkthrough's that ends by itself:
``Simulation.check_waiting`` at the horizon): an activity waiting for a performer that does
not exist is a ``deadlock``, counted in ``run.ended``'s ``deadlocks``.

Before, only the end of the run judged it: quit at d1 00:01:00, a session of a spec whose
nurse is bound to nobody traced ``run.ended`` with ``deadlocks: 0`` and no ``deadlock``,
where `opspec run SPEC --until 60 --script REC` (the replay the summary prints) traces the
nurse's check as a deadlock. What waits for the person is not judged at the quit instant:
they could still have answered."""

from __future__ import annotations

from pathlib import Path

from walkthrough_inputs import ROOT
from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.engine.trace_sinks import read_trace
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

# "check" is performed by the nurse, a ROLE participant nothing is bound to
NURSE = ROOT / "tests" / "standard_constructs" / "data" / "manual_without_implementation.xpdl"
QUIT_AT = 60.0


def _tail(trace: Path) -> list[tuple[str, float, object]]:
    """The end of a run's trace: its deadlocks, what they aborted, and ``run.ended``."""
    events = [e for e in read_trace(trace) if e.kind != "walkthrough.quit"]
    first = next(i for i, e in enumerate(events) if e.kind in ("deadlock", "run.ended"))
    return [(e.kind, e.time, e.data) for e in events[first:]]


def test_a_quit_session_traces_the_deadlocks_its_end_would(tmp_path, capsys):
    record = tmp_path / "nurse.json"
    session = WalkSession(compile_package(open_spec(NURSE)), record=record,
                          spec_path=str(NURSE))
    session.run_to(QUIT_AT)
    assert not session.ended
    session.close()                                   # q
    session.close()                                   # (the command closes it again)
    walked = record.with_suffix(".trace.jsonl")
    kinds = [e.kind for e in read_trace(walked)]
    assert kinds[-4:] == ["walkthrough.quit", "deadlock", "process.aborted", "run.ended"]
    ended = list(read_trace(walked))[-1]
    assert ended.data == {"open": 0, "deadlocks": 1}

    # the same as the replay the summary prints: opspec run --until the quit second
    trace = tmp_path / "run.trace.jsonl"
    assert main(["run", str(NURSE), "--until", repr(QUIT_AT), "--script", str(record),
                 "--trace", str(trace)]) == 1                  # (a deadlock: status 1)
    assert _tail(walked) == _tail(trace)
    capsys.readouterr()


def test_what_waits_for_the_person_is_not_a_deadlock_at_the_quit(tmp_path):
    """Quit before the clock moved, with nothing scheduled at all: the end of a run would
    take the instance waiting for the person as deadlocked ("nothing is scheduled any
    more"), but the person could still have answered."""
    kitchen = (ROOT / "tests" / "tui" / "data" / "kitchen_lanes.bpmn").read_text(
        encoding="utf-8")
    timer = ("<bpmn:timerEventDefinition><bpmn:timeDuration>PT1M</bpmn:timeDuration>"
             "</bpmn:timerEventDefinition>")
    assert timer in kitchen
    at_once = tmp_path / "kitchen.bpmn"            # the resident is asked at 00:00
    at_once.write_text(kitchen.replace(timer, ""), encoding="utf-8")
    record = tmp_path / "walk.json"
    session = WalkSession(compile_package(open_spec(at_once)), record=record,
                          spec_path=str(at_once))
    assert [o.item.activity for o in session.offers] == ["confirm"]
    assert session.sim.peek() == float("inf")
    session.close()
    events = list(read_trace(record.with_suffix(".trace.jsonl")))
    assert [e.kind for e in events[-2:]] == ["walkthrough.quit", "run.ended"]
    assert events[-1].data == {"open": 1, "deadlocks": 0}
