"""Every real-world corpus file validates without an internal error, and whether it has errors
is recorded here (with the problem that makes it so), so a change in the checks shows up as a
reviewed change of this table."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.commands.validate import engine_checks
from opspec.errors import Severity
from opspec.xpdl.validate import validate_file

CORPUS = Path("/work/shared/corpus/xpdl")
if not CORPUS.is_dir():  # pragma: no cover - the corpus lives beside the repository
    CORPUS = Path(__file__).resolve().parents[3] / "shared" / "corpus" / "xpdl"
FILES = sorted(CORPUS.glob("*.xpdl")) if CORPUS.is_dir() else []

# File -> the error codes it must have (empty: no errors). Anything not listed: no errors.
# Validation includes the engine's compilation (``not-runnable``), as ``opspec validate`` runs it.
ERRORS: dict[str, set[str]] = {
    # condition '0 <= Entity.Cost <= 5000': the package declares a field 'Cost', no 'Entity'
    "bonita-simprocess__Example6.xpdl": {"undefined-data-field"},
    # subflow targets live in other Bonita files that are not declared as ExternalPackages
    "bonita__mainSubflowJoinXor.xpdl": {"undefined-subflow"},
    "bonita__subflowParams.xpdl": {"undefined-subflow"},
    "bonita__testManagementAPIWithParsingError.xpdl": {"not-well-formed"},
    # the schema-walk artefact with "Id"/"Value" placeholders everywhere
    # (its multi-instance loops have an empty MI_Condition: no number of instances)
    "bpmve__PackageBasic.xpdl": {"dangling-transition", "duplicate-id",
                                 "missing-external-package", "multi-instance-without-count",
                                 "undefined-participant"},
    # an XPDL 2.0 sample: fields, an application and a performer it never declares, and a
    # synchronous deadline nothing catches (its Names-for-Ids resolve with warnings)
    "bpmxpdl20__sample.xpdl": {"deadline-without-exception-path", "undefined-application",
                               "undefined-data-field", "undefined-participant"},
    # transitions between a process and an activity set of another process
    "g360__Subprocess4_with_exception.xpdl": {"dangling-transition"},
    # Shark deadlines written in JavaScript (Script Type text/javascript)
    "jawe10__document_approval.xpdl": {"not-runnable"},
    "jawe10__leave_request.xpdl": {"not-runnable"},
    "jawe21__leave_request.xpdl": {"not-runnable"},
    "jawe10__sample_workflow_process.xpdl": {
        "deadline-without-exception-path", "parameter-count-mismatch", "undefined-application",
        "undefined-data-field", "undefined-participant"},
    # subflows into processes of the external package jawe21__Process_Repository.xpdl
    "jawe21__Business_Example.xpdl": {"external-subflow"},
    # a conditional event whose rule is empty
    "tibco-af__Test_multiple_pools_processes_and_lanes.xpdl": {"not-runnable"},
    # SubFlow Id="-unknown-"
    "tibcofrg___GPkNEEeyEd-eq-1NLZ2xQg.frg.xpdl": {"undefined-subflow"},
    # a Python 'timedelta(seconds=3)' deadline (shoobx.wfmc's grammar)
    "wfmc__deadline.xpdl": {"not-runnable"},
}


def _validate(path: Path):
    return validate_file(path, extra=engine_checks)


@pytest.mark.skipif(not FILES, reason="corpus not available")
@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_corpus_file_validates_without_internal_error(path: Path) -> None:
    report = _validate(path)
    codes = {d.code for d in report.diagnostics}
    assert "internal-error" not in codes
    assert all(d.location.path for d in report.diagnostics)
    errors = {d.code for d in report.diagnostics if d.severity is Severity.ERROR}
    assert errors == ERRORS.get(path.name, set())
    assert report.ok is (not errors)
    # every error is located at a line of a file
    assert all(d.location.line for d in report.diagnostics if d.severity is Severity.ERROR)


@pytest.mark.skipif(not FILES, reason="corpus not available")
@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_validate_and_run_agree(path: Path) -> None:
    """What validate accepts, the engine compiles and runs (a day of simulated time); what it
    refuses, ``opspec run`` refuses before running. A run may still stop on a fault of the
    spec's behaviour (an ExecutionError), never on a SpecError; one that stops with its clock
    stopped in a zero-time cycle was warned of by validate (bonita__arbitraryCycle.xpdl was
    validated clean and stopped at t = 0)."""
    from opspec.commands._spec import load_any_spec
    from opspec.engine.compiled import compile_package
    from opspec.engine.simulation import Simulation
    from opspec.errors import ExecutionError, SpecError, ZeroTimeCycleError

    report = _validate(path)
    if not report.ok:
        with pytest.raises(SpecError):
            compile_package(load_any_spec(path))
        return
    compiled = compile_package(load_any_spec(path))
    try:
        Simulation(compiled, seed=0).run(until=24 * 3600)
    except SpecError:                       # pragma: no cover - the failure this test catches
        raise
    except ZeroTimeCycleError:
        assert "zero-time-cycle" in {d.code for d in report.diagnostics}, (
            "the run stopped in a zero-time cycle validate said nothing of")
    except ExecutionError:
        pass


def _report(name: str) -> list[str]:
    path = CORPUS / name
    if not path.is_file():
        pytest.skip("corpus not available")
    return [str(d) for d in validate_file(path).diagnostics]


def test_loop_blocked_example_breaks_its_declared_conformance_class() -> None:
    lines = _report("jawe10__LoopBlocked.xpdl")
    cycle = [line for line in lines if "declares graph conformance LOOP_BLOCKED" in line]
    assert len(cycle) == 1
    assert ":83: warning:" in cycle[0] and "process 'LOOP_BLOCKED_Test_Wor1'" in cycle[0]
    assert "LOOP_BLOCKED_Test_Wor1_Act4 -> LOOP_BLOCKED_Test_Wor1_Act3" in cycle[0]


def test_g360_transitions_crossing_processes_are_dangling() -> None:
    lines = _report("g360__Subprocess4_with_exception.xpdl")
    assert any(line.endswith(":165: error: Transition '436' comes from activity '364', which "
                             "is not in process '1' (activity ids are scoped per process) ('364' "
                             "is an activity of process '2': set From to an activity of process "
                             "'1', or move the transition there)") for line in lines)
    assert sum("dangling" in line or "is not in process" in line for line in lines) == 6


def test_e_car_case_study_may_deadlock_at_its_and_joins() -> None:
    lines = _report("tibco-af__Fallstudie_4-09_e-Car_Produktion.xpdl")
    joins = [line for line in lines if "AND-join" in line]
    assert len(joins) == 2 and all(": warning: " in line for line in joins)


def test_wfmc_deadline_sample_places_activities_in_lanes_it_does_not_declare() -> None:
    lines = _report("wfmc__deadline.xpdl")
    assert sum("which no pool of the package declares" in line for line in lines) == 6
