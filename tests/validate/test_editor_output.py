"""Issue 17: validate, compile, run, check and show agree, and real editor output is accepted
where the XPDL schema and the editor's own engine accept it."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.commands.validate import engine_checks
from opspec.engine.compiled import compile_package
from opspec.engine.simulation import Simulation
from opspec.errors import Severity
from opspec.xpdl.loader import load_package
from opspec.xpdl.validate import validate_file

HEAD = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="demo">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2024</Created></PackageHeader>
"""


def spec(tmp_path: Path, body: str, name: str = "spec.xpdl") -> Path:
    path = tmp_path / name
    path.write_text(HEAD + body + "\n</Package>\n", encoding="utf-8")
    return path


def codes(path: Path, severity: Severity | None = None) -> list[str]:
    report = validate_file(path, extra=engine_checks)
    return [d.code for d in report.diagnostics if severity is None or d.severity is severity]


def runs(path: Path) -> dict:
    package = load_package(path).package
    assert package is not None
    return Simulation(compile_package(package), seed=0, keep_trace=True).run(
        until=3600).summary


FLOW = """
  <WorkflowProcesses>
    <WorkflowProcess Id="P">
      {fields}
      <Activities>
        <Activity Id="start"><Event><StartEvent/></Event></Activity>
        <Activity Id="work"{work_attrs}>{work}</Activity>
        <Activity Id="end"><Event><EndEvent/></Event></Activity>
      </Activities>
      <Transitions>
        <Transition Id="t1" From="start" To="work"/>
        <Transition Id="t2" From="work" To="end">{condition}</Transition>
      </Transitions>
    </WorkflowProcess>
  </WorkflowProcesses>"""


def flow(*, fields: str = "", work: str = "<Implementation><No/></Implementation>",
         condition: str = "", work_attrs: str = "", before: str = "") -> str:
    return before + FLOW.format(fields=fields, work=work, condition=condition,
                                work_attrs=work_attrs)


# -- validate reports what the engine refuses, at its line --------------------------------

def test_an_unreadable_deadline_is_a_located_error_of_validate_and_compile_writes_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # (a deadline with no duration is valid XPDL 2.x and never expires: a warning, it runs;
    # tests/validate/test_deadline_refusal.py)
    path = spec(tmp_path, flow(work="<Implementation><No/></Implementation>"
                               "<Deadline><DeadlineDuration>timedelta(seconds=3)"
                               "</DeadlineDuration></Deadline>"))
    text = path.read_text(encoding="utf-8")
    assert codes(path, Severity.ERROR) == ["not-runnable"]
    assert main(["validate", str(path)]) == 1
    out = capsys.readouterr().out
    line = next(n for n, row in enumerate(text.splitlines(), 1) if "<Deadline>" in row)
    assert f"{path}:{line}: error: deadline of activity 'work'" in out
    target = tmp_path / "out.wfs"
    assert main(["compile", str(path), "-o", str(target)]) == 1
    assert not target.exists()
    assert main(["show", str(path)]) == 1
    assert f"{path}:{line}: error: deadline of activity 'work'" in capsys.readouterr().err


def test_a_javascript_deadline_names_the_script_language(tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]
                                                         ) -> None:
    path = spec(tmp_path, '<Script Type="text/javascript"/>' + flow(
        work="<Implementation><No/></Implementation><Deadline><DeadlineDuration>"
             "var d=new java.util.Date(); d;</DeadlineDuration></Deadline>"))
    assert main(["validate", str(path)]) == 1
    out = capsys.readouterr().out
    assert "error: deadline of activity 'work'" in out
    assert "Script Type 'text/javascript'" in out


def test_check_refuses_a_spec_with_a_dangling_transition(tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    path = spec(tmp_path, flow().replace('To="end"', 'To="nowhere"'))
    assert "dangling-transition" in codes(path, Severity.ERROR)
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out
    assert "Transition 't2' points to activity 'nowhere'" in out
    assert "not sound (the spec has errors)" in out


# -- scoping ------------------------------------------------------------------------------

def test_a_process_level_application_hides_the_package_level_one(tmp_path: Path) -> None:
    # the shape of the WfMC publication sample: the package's 'prepare' has a formal
    # parameter, the process's own 'prepare' has none, and the task passes none
    body = """
  <Applications><Application Id="prepare"><FormalParameters>
    <FormalParameter Id="x" Mode="OUT"><DataType><BasicType Type="BOOLEAN"/></DataType></FormalParameter>
  </FormalParameters></Application></Applications>""" + flow(
        work='<Implementation><Task><TaskApplication Id="prepare"/></Task></Implementation>'
    ).replace('<WorkflowProcess Id="P">', '<WorkflowProcess Id="P"><Applications>'
              '<Application Id="prepare"/></Applications>')
    path = spec(tmp_path, body)
    assert codes(path, Severity.ERROR) == []
    assert runs(path)["instances"]["completed"] == 1


def test_a_lane_may_name_a_participant_of_its_own_process(tmp_path: Path) -> None:
    body = """
  <Pools><Pool Id="pool" Process="P"><Lanes><Lane Id="lane"><Performers>
    <Performer>clerk</Performer></Performers></Lane></Lanes></Pool></Pools>""" + flow().replace(
        '<WorkflowProcess Id="P">', '<WorkflowProcess Id="P"><Participants><Participant '
        'Id="clerk"><ParticipantType Type="SYSTEM"/></Participant></Participants>')
    path = spec(tmp_path, body)
    assert "undefined-participant" not in codes(path)
    other = spec(tmp_path, body.replace("<Performer>clerk</Performer>",
                                        "<Performer>ghost</Performer>"), "other.xpdl")
    assert "undefined-participant" in codes(other, Severity.ERROR)


def test_a_formal_parameter_and_a_data_field_with_one_id_are_one_variable(tmp_path: Path
                                                                          ) -> None:
    fields = """<FormalParameters><FormalParameter Id="n" Mode="IN"><DataType><BasicType
      Type="INTEGER"/></DataType></FormalParameter></FormalParameters>
      <DataFields><DataField Id="n"><DataType><BasicType Type="INTEGER"/></DataType>
      <InitialValue>3</InitialValue></DataField></DataFields>"""
    path = spec(tmp_path, flow(fields=fields))
    assert codes(path, Severity.ERROR) == []
    assert "parameter-data-field" in codes(path, Severity.WARNING)


# -- editor constructs -------------------------------------------------------------------

def test_an_unhandled_asynchronous_deadline_is_a_warning_and_does_not_abort(tmp_path: Path
                                                                            ) -> None:
    work = ('<Implementation><No/></Implementation><Deadline Execution="ASYNCHR">'
            '<DeadlineDuration>PT1S</DeadlineDuration><ExceptionName>late</ExceptionName>'
            '</Deadline>')
    path = spec(tmp_path, flow(work=work))
    assert codes(path, Severity.ERROR) == []
    assert "unhandled-deadline" in codes(path, Severity.WARNING)
    synchronous = spec(tmp_path, flow(work=work.replace("ASYNCHR", "SYNCHR")), "sync.xpdl")
    assert "deadline-without-exception-path" in codes(synchronous, Severity.ERROR)


def test_a_field_read_by_its_name_resolves_to_its_id_with_a_warning(tmp_path: Path) -> None:
    fields = """<DataFields><DataField Id="_gen1" Name="amount"><DataType><BasicType
      Type="INTEGER"/></DataType><InitialValue>5</InitialValue></DataField></DataFields>"""
    split = ('<TransitionRestrictions><TransitionRestriction><Split Type="Exclusive"/>'
             '</TransitionRestriction></TransitionRestrictions>')
    path = spec(tmp_path, flow(
        fields=fields, work="<Implementation><No/></Implementation>" + split,
        condition='<Condition Type="CONDITION"><Expression>amount &gt; 3</Expression>'
                  '</Condition>'))
    report = validate_file(path, extra=engine_checks)
    assert report.ok
    warning = next(d for d in report.diagnostics if d.code == "field-by-name")
    assert "'amount' is the Name of data field '_gen1'" in warning.message
    assert warning.location.line is not None
    assert runs(path)["instances"]["completed"] == 1


def test_a_name_that_is_also_an_id_keeps_meaning_the_id(tmp_path: Path) -> None:
    fields = """<DataFields><DataField Id="amount" Name="x"><DataType><BasicType
      Type="INTEGER"/></DataType></DataField><DataField Id="_gen1" Name="amount"><DataType>
      <BasicType Type="INTEGER"/></DataType></DataField></DataFields>"""
    path = spec(tmp_path, flow(fields=fields, condition='<Condition Type="CONDITION">'
                               '<Expression>amount &gt; 3</Expression></Condition>'))
    assert "field-by-name" not in codes(path)


def test_a_text_grammar_condition_is_a_label(tmp_path: Path) -> None:
    path = spec(tmp_path, flow(condition='<Condition Type="CONDITION"><Expression '
                               'ScriptGrammar="Text">Parts needed</Expression></Condition>'))
    assert codes(path, Severity.ERROR) == []
    assert "text-condition" in codes(path, Severity.WARNING)
    package = load_package(path).package
    assert package is not None
    transition = package.processes[0].transitions[1]
    assert transition.condition.text == "Parts needed" and transition.condition.expression is None
    assert runs(path)["instances"]["completed"] == 1
