"""Token quantities: BPMN startQuantity / completionQuantity, XPDL 2.1 StartQuantity /
CompletionQuantity and Transition Quantity (thread merge WCP-41, thread split WCP-42)."""

from __future__ import annotations

from pathlib import Path

from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

from .conftest import DATA, completed, run


def test_bpmn_completion_and_start_quantity() -> None:
    """BPMN 2.0 Table 10.3 (Activity): "completionQuantity … defines the number of tokens that
    MUST be generated from the Activity. This number of tokens will be sent done any outgoing
    Sequence Flow"; "startQuantity … defines the number of tokens that MUST arrive before the
    Activity can begin." Workflow patterns (2006), WCP-42 Thread Split: "At a given point in a
    process, a nominated number of execution threads can be initiated in a single branch of
    the same process instance"; WCP-41 Thread Merge: "… a nominated number of execution
    threads in a single branch of the same process instance should be merged together into a
    single thread of execution."

    "split" (completionQuantity 3) runs "work" three times at once; "merge" (startQuantity 3)
    starts once, when all three tokens have arrived, and the instance completes."""
    outcome = run("thread_split_merge.bpmn", until=60)
    assert completed(outcome) == [(0.0, "start"), (0.0, "split"), (1.0, "work"), (1.0, "work"),
                                  (1.0, "work"), (1.0, "merge"), (1.0, "end")]
    assert outcome.summary["instances"]["completed"] == 1


def test_xpdl_quantities_multiply_and_merge_per_start_quantity() -> None:
    """XPDL 2.1 Activity StartQuantity / CompletionQuantity and Transition Quantity (the BPMN
    attributes above; a transition's Quantity is the number of tokens it carries, as BPMN
    1.x's sequence flow Quantity: "the number of Tokens that will be generated down the
    Sequence Flow"). CompletionQuantity 2 on a transition of Quantity 2: four tokens run
    "work"; StartQuantity 2: "merge" starts once per two of them — twice."""
    outcome = run("thread_split_merge.xpdl", until=60)
    names = [name for _t, name in completed(outcome)]
    assert names.count("work") == 4
    assert names.count("merge") == 2 and names.count("end") == 2
    assert outcome.summary["instances"]["completed"] == 1


def test_a_quantity_that_is_no_whole_number_is_a_located_error(tmp_path: Path) -> None:
    """A value that changes behaviour is never read as its default in silence: a quantity
    that is not a whole number of 1 or more is an error at its line."""
    text = (DATA / "thread_split_merge.xpdl").read_text(encoding="utf-8")
    bad = tmp_path / "bad.xpdl"
    bad.write_text(text.replace('StartQuantity="2"', 'StartQuantity="two"'), encoding="utf-8")
    _package, report = validate_spec(bad)
    errors = [(d.location.line, d.code) for d in report.diagnostics
              if d.severity is Severity.ERROR]
    assert errors == [(13, "bad-quantity")]   # the line of "merge"
