"""Synchronous recursion: a subflow that calls itself until a base case runs (XPDL 2.1 puts
no limit on SubFlow nesting); runaway recursion ends with a located fault at a documented
depth; only recursion that cannot end (the call is on every path) is refused by validate."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.interpreter import MAX_CALL_DEPTH
from opspec.engine.simulation import Simulation
from opspec.errors import SpecError
from opspec.xpdl.loader import load_package, load_spec

FACTORIAL = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="rec"><PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created></PackageHeader>
<WorkflowProcesses>
<WorkflowProcess Id="main"><ProcessHeader/>
<DataFields><DataField Id="r"><DataType><BasicType Type="INTEGER"/></DataType><InitialValue>0</InitialValue></DataField></DataFields>
<Activities><Activity Id="call"><Implementation><SubFlow Id="fact"><ActualParameters><ActualParameter>N</ActualParameter><ActualParameter>r</ActualParameter></ActualParameters></SubFlow></Implementation></Activity></Activities>
</WorkflowProcess>
<WorkflowProcess Id="fact"><ProcessHeader/>
<FormalParameters><FormalParameter Id="n" Mode="IN"><DataType><BasicType Type="INTEGER"/></DataType></FormalParameter><FormalParameter Id="out" Mode="OUT"><DataType><BasicType Type="INTEGER"/></DataType></FormalParameter></FormalParameters>
<DataFields><DataField Id="sub"><DataType><BasicType Type="INTEGER"/></DataType><InitialValue>0</InitialValue></DataField></DataFields>
<Activities>
<Activity Id="test"><Route GatewayType="Exclusive"/><TransitionRestrictions><TransitionRestriction><Split Type="Exclusive"/></TransitionRestriction></TransitionRestrictions></Activity>
<Activity Id="base"><Implementation><No/></Implementation><Assignments><Assignment><Target>out</Target><Expression>1</Expression></Assignment></Assignments></Activity>
<Activity Id="recurse"><Implementation><SubFlow Id="fact"><ActualParameters><ActualParameter>n - 1</ActualParameter><ActualParameter>sub</ActualParameter></ActualParameters></SubFlow></Implementation><Assignments><Assignment><Target>out</Target><Expression>n * sub</Expression></Assignment></Assignments></Activity>
</Activities>
<Transitions><Transition Id="t1" From="test" To="base"><Condition Type="CONDITION"><Expression>BASE</Expression></Condition></Transition><Transition Id="t2" From="test" To="recurse"><Condition Type="OTHERWISE"/></Transition></Transitions>
</WorkflowProcess>
</WorkflowProcesses></Package>
"""


def write(tmp_path: Path, n: int, base: str = "n &lt;= 1") -> Path:
    path = tmp_path / "rec.xpdl"
    path.write_text(FACTORIAL.replace("BASE", base).replace(">N<", f">{n}<"))
    return path


def test_bounded_recursion_runs_to_its_base_case(tmp_path: Path) -> None:
    path = write(tmp_path, 5)
    assert load_package(path).ok
    sim = Simulation(load_spec(path), keep_trace=True)
    result = sim.run()
    assert result.summary["faults"] == []
    assert result.summary["instances"]["completed"] == 6      # main and fact(5)..fact(1)
    changed = [e.data for e in result.trace or () if e.kind == "data.changed"
               and e.process == "main"]
    assert changed == [{"r": 120}]


def test_runaway_recursion_ends_with_one_located_fault_at_the_depth_limit(
        tmp_path: Path) -> None:
    path = write(tmp_path, 5, base="n &gt; 1000")        # the base case is never reached
    result = Simulation(load_spec(path)).run()
    [fault] = result.summary["faults"]
    assert fault["message"].startswith(f"{path}:")
    assert f"{MAX_CALL_DEPTH + 1} synchronous subflow calls deep" in fault["message"]
    assert result.summary["instances"]["open"] == 0


def test_recursion_without_a_base_case_is_refused(tmp_path: Path) -> None:
    text = FACTORIAL.replace('<Condition Type="CONDITION"><Expression>BASE</Expression>'
                             '</Condition>', "").replace(
        '<Transition Id="t2" From="test" To="recurse"><Condition Type="OTHERWISE"/>'
        '</Transition>', '<Transition Id="t2" From="base" To="recurse"/>')
    path = tmp_path / "rec.xpdl"
    path.write_text(text.replace(">N<", ">3<"))
    with pytest.raises(SpecError, match="subflows call each other in a cycle"):
        load_spec(path)
