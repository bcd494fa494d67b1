"""A terminate end event inside an embedded sub-process (BPMN ``subProcess``, XPDL 2.1
``BlockActivity`` / ``ActivitySet``) ends that sub-process only; the parent goes on."""

from __future__ import annotations

import pytest

from .conftest import completed, kinds, run


@pytest.mark.parametrize("name", ["terminate_in_subprocess.bpmn",
                                  "terminate_in_activity_set.xpdl"])
def test_terminate_end_event_ends_only_its_sub_process(name: str) -> None:
    """BPMN 2.0 §13.3.4 (Sub-Process): "If a 'terminate' End Event is reached, the
    Sub-Process is abnormally terminated." §13.5.6: "For a 'terminate' End Event, the Process
    is abnormally terminated—no other ongoing Process instances are affected."

    The branch "quick" (1 s) reaches the terminate end event while "slow" (10 s) still runs:
    "slow" is ended with the sub-process at t=1, which then completes, and the parent goes on
    along its outgoing flow ("after", 1 s) and completes normally — it is not terminated."""
    outcome = run(name, until=60)
    assert completed(outcome) == [
        (0.0, "start"), (0.0, "sub_start"), (0.0, "fork"), (1.0, "quick"), (1.0, "kill"),
        (1.0, "sub"), (2.0, "after"), (2.0, "end")]
    assert [e.time for e in kinds(outcome, "process.completed")] == [2.0]
    assert not kinds(outcome, "process.terminated")
    assert not kinds(outcome, "process.aborted")


def test_terminate_end_event_of_the_process_still_ends_the_instance() -> None:
    """BPMN 2.0 §13.5.6: "For a 'terminate' End Event, the Process is abnormally terminated"
    — at process level the whole instance ends, its other branches with it."""
    outcome = run("terminate_at_process_level.bpmn", until=60)
    assert completed(outcome) == [(0.0, "start"), (0.0, "fork"), (1.0, "quick"), (1.0, "kill")]
    assert [e.time for e in kinds(outcome, "process.terminated")] == [1.0]
    assert not kinds(outcome, "process.completed")
