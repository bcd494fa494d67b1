"""A flow node with incoming sequence flows never starts when its process starts, even when
every flow into it comes from something opspec does not run."""

from __future__ import annotations

from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

from .conftest import DATA, completed, kinds, run


def test_nodes_reached_only_from_unrun_boundary_events_do_not_start() -> None:
    """BPMN 2.0 §10.4.2 (Start Event): "all Flow Objects that do not have an incoming Sequence
    Flow (i.e., are not a target of a Sequence Flow) SHALL be instantiated when the Process is
    instantiated" — and only those: "cancelled", "undo" and "notify" are targets of sequence
    flows (from a cancel and a compensation boundary event, which opspec does not run), so
    they never start; the run is the transaction and nothing else."""
    outcome = run("flows_from_what_never_runs.bpmn", until=60)
    assert completed(outcome) == [(0.0, "start"), (0.0, "b_start"), (1.0, "reserve"),
                                  (1.0, "b_end"), (1.0, "book"), (1.0, "end")]
    assert [e.time for e in kinds(outcome, "process.completed")] == [1.0]


def test_validate_says_at_their_lines_that_those_events_never_fire() -> None:
    """What opspec does instead is said at the line of each boundary event it does not run."""
    _package, report = validate_spec(DATA / "flows_from_what_never_runs.bpmn")
    said = {(d.location.line, d.code) for d in report.diagnostics
            if d.severity is Severity.WARNING and "never fires" in d.message}
    assert said == {(15, "unsupported-element"), (16, "unsupported-element")}
