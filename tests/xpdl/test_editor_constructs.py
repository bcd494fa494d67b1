"""Constructs written by XPDL editors, read and run as the standard says (issue 16):
a Condition's text beside an empty ``<Expression/>`` (JaWE/TWE), array and record data with
JSON initial values flowing into the coordination built-ins."""

from __future__ import annotations

from typing import Any

import pytest

from opspec.engine.simulation import Simulation
from opspec.errors import SpecError
from opspec.model import ConditionKind, Package, codec
from opspec.xpdl.loader import parse_bytes
from opspec.xpdl.writer import write_xpdl


def load(text: str, path: str = "spec.xpdl") -> Package:
    result = parse_bytes(text.encode(), path=path)
    assert result.package is not None and result.ok, [str(d) for d in result.diagnostics]
    return result.package


def run(package: Package, until: float = 10.0) -> Any:
    return Simulation(package, keep_trace=True).run(until=until)


def completed(result: Any) -> list[str]:
    return [e.activity for e in result.trace if e.kind == "activity.completed" and e.activity]


JAWE_CONDITIONS = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="jawe" Name="jawe">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>Together</Vendor><Created>2024</Created></PackageHeader>
  <WorkflowProcesses>
    <WorkflowProcess Id="w">
      <ProcessHeader/>
      <DataFields>
        <DataField Id="x"><DataType><BasicType Type="INTEGER"/></DataType><InitialValue>3</InitialValue></DataField>
      </DataFields>
      <Activities>
        <Activity Id="decide"><Route GatewayType="Exclusive"/>
          <TransitionRestrictions><TransitionRestriction><Split Type="Exclusive"><TransitionRefs>
            <TransitionRef Id="small"/><TransitionRef Id="big"/></TransitionRefs></Split>
          </TransitionRestriction></TransitionRestrictions></Activity>
        <Activity Id="few"><Implementation><No/></Implementation></Activity>
        <Activity Id="many"><Implementation><No/></Implementation></Activity>
      </Activities>
      <Transitions>
        <Transition Id="small" From="decide" To="few"><Condition Type="CONDITION">x &lt; 2<Expression/></Condition></Transition>
        <Transition Id="big" From="decide" To="many"><Condition Type="CONDITION"><Expression/>x &gt; 1</Condition></Transition>
      </Transitions>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""


def test_condition_text_beside_an_empty_expression_is_kept_and_decides() -> None:
    package = load(JAWE_CONDITIONS)
    conditions = {t.id: t.condition for t in package.processes[0].transitions}
    assert conditions["small"].kind is ConditionKind.CONDITION
    assert conditions["small"].text == "x < 2"
    assert conditions["big"].text == "x > 1"
    assert conditions["small"].expression is not None
    assert completed(run(package)) == ["decide", "many"]


def test_condition_text_beside_an_empty_expression_survives_writing_back() -> None:
    package = load(JAWE_CONDITIONS)
    again = load(write_xpdl(package).decode(), path="again.xpdl")
    assert [t.condition.text for t in again.processes[0].transitions] == ["x < 2", "x > 1"]


def test_a_bad_condition_beside_an_empty_expression_is_a_located_error() -> None:
    text = JAWE_CONDITIONS.replace("x &lt; 2<Expression/>", "x &lt;&lt; 2<Expression/>")
    result = parse_bytes(text.encode(), path="spec.xpdl")
    errors = [d for d in result.diagnostics if d.code == "bad-condition"]
    assert len(errors) == 1 and errors[0].location.line == 19


VECTORS = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" xmlns:opspec="urn:opspec:sisarl:1" Id="robot" Name="robot">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>opspec</Vendor><Created>2024</Created></PackageHeader>
  <TypeDeclarations>
    <TypeDeclaration Id="Vector2"><ArrayType LowerIndex="0" UpperIndex="1"><BasicType Type="FLOAT"/></ArrayType></TypeDeclaration>
    <TypeDeclaration Id="Pose"><RecordType>
      <Member Name="x"><BasicType Type="FLOAT"/></Member><Member Name="y"><BasicType Type="FLOAT"/></Member>
    </RecordType></TypeDeclaration>
  </TypeDeclarations>
  <DataFields>
    <DataField Id="avoid"><DataType><ArrayType LowerIndex="0" UpperIndex="1"><BasicType Type="FLOAT"/></ArrayType></DataType>
      <InitialValue>[1.0, -2.0]</InitialValue></DataField>
    <DataField Id="seek"><DataType><DeclaredType Id="Vector2"/></DataType><InitialValue>[0.5, 4]</InitialValue></DataField>
    <DataField Id="drive"><DataType><DeclaredType Id="Vector2"/></DataType></DataField>
    <DataField Id="pose"><DataType><DeclaredType Id="Pose"/></DataType><InitialValue>{"x": 2.5, "y": 1}</InitialValue></DataField>
    <DataField Id="far"><DataType><BasicType Type="BOOLEAN"/></DataType><InitialValue>false</InitialValue></DataField>
  </DataFields>
  <WorkflowProcesses>
    <WorkflowProcess Id="guide">
      <ProcessHeader/>
      <Activities>
        <Activity Id="combine"><Implementation><No/></Implementation>
          <ExtendedAttributes><ExtendedAttribute Name="opspec:BuiltIn">
            <opspec:Superposition Output="drive">
              <opspec:Input Ref="avoid" Weight="2"/><opspec:Input Ref="seek"/>
            </opspec:Superposition>
          </ExtendedAttribute></ExtendedAttributes>
        </Activity>
        <Activity Id="where"><Implementation><No/></Implementation>
          <Assignments><Assignment AssignTime="End"><Target>far</Target><Expression>pose.x &gt; 2</Expression></Assignment></Assignments>
        </Activity>
      </Activities>
      <Transitions><Transition Id="t" From="combine" To="where"/></Transitions>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""


def test_vector_superposition_runs_from_a_spec() -> None:
    """Arrays with JSON initial values (an inline ArrayType and a declared one) flow into the
    superposition built-in: drive = 2 * avoid + seek, element by element; a record's member
    is read with a dotted name."""
    result = run(load(VECTORS))
    changes = [(e.activity, dict(e.data)) for e in result.trace if e.kind == "data.changed"]
    assert changes == [("combine", {"drive": [2.5, 0.0]}), ("where", {"far": True})]
    assert completed(result) == ["combine", "where"]


def test_array_data_round_trips_through_the_writer_and_the_wfs_codec() -> None:
    package = load(VECTORS)
    assert codec.loads(codec.dumps(package)) == package
    again = load(write_xpdl(package).decode(), path="again.xpdl")
    fields = {f.id: f for f in again.data_fields}
    assert fields["avoid"].initial_value == "[1.0, -2.0]"
    result = run(again)
    assert next(dict(e.data) for e in result.trace if e.kind == "data.changed") == {
        "drive": [2.5, 0.0]}


XPDL10_ARRAY = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2002/XPDL1.0" Id="p" Name="p">
  <PackageHeader><XPDLVersion>1.0</XPDLVersion><Vendor>t</Vendor><Created>2024</Created></PackageHeader>
  <DataFields>
    <DataField Id="a" IsArray="TRUE"><DataType><BasicType Type="INTEGER"/></DataType><InitialValue>{value}</InitialValue></DataField>
    <DataField Id="b" IsArray="TRUE"><DataType><BasicType Type="INTEGER"/></DataType><InitialValue>[10, 20, 30]</InitialValue></DataField>
    <DataField Id="s"><DataType><BasicType Type="INTEGER"/></DataType></DataField>
  </DataFields>
  <WorkflowProcesses><WorkflowProcess Id="w"><ProcessHeader/>
    <Activities><Activity Id="sum"><Implementation><No/></Implementation>
      <ExtendedAttributes><ExtendedAttribute Name="opspec:BuiltIn">
        <opspec:Superposition xmlns:opspec="urn:opspec:sisarl:1" Output="s"><opspec:Input Ref="a"/><opspec:Input Ref="b" Weight="-1"/></opspec:Superposition>
      </ExtendedAttribute></ExtendedAttributes></Activity></Activities>
  </WorkflowProcess></WorkflowProcesses>
</Package>
"""


def test_xpdl10_isarray_fields_take_json_lists() -> None:
    result = run(load(XPDL10_ARRAY.format(value="[1, 2, 3]")))
    assert [dict(e.data) for e in result.trace if e.kind == "data.changed"] == [
        {"s": [-9.0, -18.0, -27.0]}]


@pytest.mark.parametrize(("value", "problem"), [
    ("5", "an array's initial value is a JSON list"),
    ("[1, 2", "is not a JSON value"),
    ("{1: 2}", "is not a JSON value"),
])
def test_bad_array_initial_values_are_located_errors(value: str, problem: str) -> None:
    result = parse_bytes(XPDL10_ARRAY.format(value=value).encode(), path="a.xpdl")
    errors = [d for d in result.diagnostics if d.code == "bad-initial-value"]
    assert len(errors) == 1 and errors[0].location.line == 5
    assert problem in errors[0].message and "'a'" in errors[0].message


def test_a_declared_array_with_a_bad_initial_value_is_refused_at_compile_time() -> None:
    text = VECTORS.replace("<InitialValue>[0.5, 4]</InitialValue>", "<InitialValue>0.5</InitialValue>")
    with pytest.raises(SpecError, match="'seek'.*JSON list") as caught:
        Simulation(load(text))
    assert caught.value.location is not None and caught.value.location.line == 13
