"""An XPDL activity with no implementation performed by a person is manual work: it is offered
to its performer, or waits for one, and is never an automatic zero-time step."""

from __future__ import annotations

from opspec.engine.builtin_performers import SimulatedDevice
from opspec.xpdl.dot import package_to_dot
from opspec.xpdl.loader import load_spec

from .conftest import DATA, completed, kinds, run


def test_manual_work_waits_for_its_performer_and_is_reported_as_waiting() -> None:
    """XPDL 2.1 (WfMC-TC-1025) §7.6.5.1, No Implementation: an activity whose
    Implementation is "No" is "implemented by manual procedures"; §7.7: a ROLE or HUMAN
    participant is a person who performs it.

    With nobody bound for the nurse (a ROLE participant: XPDL's
    default type), "check" is offered at 15 s to no performer and waits; at the horizon the
    run reports it as waiting work. The SYSTEM participant's "log", the unperformed "note" and
    the nurse's "auto" (opspec:AutoRun="true") run by themselves for their 5 s."""
    outcome = run("manual_without_implementation.xpdl", until=100)
    assert completed(outcome) == [(0, "start"), (5.0, "log"), (10.0, "note"), (15.0, "auto")]
    offered = [(e.time, e.activity, e.data) for e in kinds(outcome, "activity.offered")]
    assert offered == [(15.0, "check", {"performer": None})]
    (waiting,) = outcome.summary["deadlocks"]
    assert waiting["waiting"] == ["check (performer for participant 'nurse' / lanes -)"]
    assert outcome.problems


def test_manual_work_is_offered_to_the_bound_performer() -> None:
    """XPDL 2.1 (WfMC-TC-1025) §7.6.5.1, No Implementation: an activity whose
    Implementation is "No" is "implemented by manual procedures"; §7.7: a ROLE or HUMAN
    participant is a person who performs it.

    Bound to a performer, the nurse's "check" is offered to it
    (not run by the engine) and completes when the performer does, after its 5 s."""
    outcome = run("manual_without_implementation.xpdl", until=100,
                  performers={"nurse": SimulatedDevice()})
    assert completed(outcome)[-2:] == [(20.0, "check"), (20.0, "end")]
    assert [e.activity for e in kinds(outcome, "activity.offered")] == ["check"]
    assert not outcome.summary["deadlocks"]


def test_show_and_the_model_call_it_manual() -> None:
    """XPDL 2.1 (WfMC-TC-1025) §7.6.5.1, No Implementation: an activity whose
    Implementation is "No" is "implemented by manual procedures"; §7.7: a ROLE or HUMAN
    participant is a person who performs it.

    What the model says of each activity (show, the pictures) is
    what the run does."""
    package = load_spec(DATA / "manual_without_implementation.xpdl")
    (process,) = package.processes
    manual = {a.id for a in process.activities if package.is_manual_work(a, process)}
    assert manual == {"check"}
    drawn = package_to_dot(package)
    assert [line.split()[0] for line in drawn.splitlines() if "(manual)" in line] == ['"check"']


def test_a_bpmn_file_written_as_xpdl_keeps_its_abstract_tasks_automatic(tmp_path) -> None:
    """BPMN 2.0 §10.2.3 (Task): an abstract task, one "not further specified", runs by itself;
    XPDL 2.1 §7.6.5.1 reads an activity without an implementation performed by a lane's ROLE
    participant as manual work. The bundled BPMN dispenser written as XPDL (`opspec
    preprocess`) says opspec:AutoRun="true" for its abstract tasks, and runs as the BPMN file
    does: the same doses, the same instances."""
    import opspec
    from opspec.xpdl.writer import write_xpdl

    source = DATA.parents[2] / "specs" / "medication_dispenser.bpmn"
    written = tmp_path / "medication_dispenser.xpdl"      # its user model beside it, as
    written.write_bytes(write_xpdl(load_spec(source)))    # preprocess copies it
    users = source.with_name("medication_dispenser.users.toml")
    written.with_name(users.name).write_bytes(users.read_bytes())
    assert b"opspec:AutoRun" in written.read_bytes()
    runs = [opspec.run(path, seed=0, days=2) for path in (source, written)]
    assert runs[0].summary["instances"] == runs[1].summary["instances"]
    assert runs[0].metrics == runs[1].metrics
    assert runs[1].summary["deadlocks"] == []
