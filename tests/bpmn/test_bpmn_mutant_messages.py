"""What the mutation harness (benchmarks/mutation_fuzz.py) found in damaged BPMN files: each
message is true of the file and names its line, and validate refuses what run refuses."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

HEAD = ('<?xml version="1.0" encoding="UTF-8"?>\n'
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
        'id="d">\n<bpmn:process id="p" isExecutable="true">\n')
TAIL = '</bpmn:process>\n</bpmn:definitions>\n'


def _errors(tmp_path: Path, body: str) -> list[str]:
    path = tmp_path / "damaged.bpmn"
    path.write_text(HEAD + body + TAIL, encoding="utf-8")
    report = validate_spec(path)[1]
    return [str(d) for d in report.diagnostics if d.severity is Severity.ERROR]


TIMER = ('<bpmn:startEvent id="s"/>\n'
         '<bpmn:receiveTask id="wait"/>\n'
         '<bpmn:boundaryEvent id="late" attachedToRef="wait">\n'
         '  <bpmn:timerEventDefinition>{timer}</bpmn:timerEventDefinition>\n'
         '</bpmn:boundaryEvent>\n'
         '<bpmn:endEvent id="e"/>\n<bpmn:endEvent id="e2"/>\n'
         '<bpmn:sequenceFlow id="f1" sourceRef="s" targetRef="wait"/>\n'
         '<bpmn:sequenceFlow id="f2" sourceRef="wait" targetRef="e"/>\n'
         '<bpmn:sequenceFlow id="f3" sourceRef="late" targetRef="e2"/>\n')


def test_an_emptied_boundary_timer_is_one_error_and_no_flow_blamed_on_another_process(
        tmp_path: Path) -> None:
    # the timer's flow 'f3' was said to start at "a bpmn:boundaryEvent of another process or
    # sub-process": the event is in this very process, left out for its empty timer
    errors = _errors(tmp_path, TIMER.format(timer="<bpmn:timeDuration></bpmn:timeDuration>"))
    assert len(errors) == 1, errors
    assert errors[0].startswith(f"{tmp_path / 'damaged.bpmn'}:7: error: boundary timer 'late' "
                                "has an empty timeDuration")
    assert "another process" not in errors[0]


@pytest.mark.parametrize(("duration", "said"), [
    ("PT", "cannot read duration 'PT'"),
    ("PT5M5M", "cannot read duration 'PT5M5M'"),
    ("-PT5M", "cannot read duration '-PT5M'"),
    ("P-1D", "cannot read duration 'P-1D'"),
    ("R3/PT5M", "it is a repeating interval (a cycle), not a duration"),
])
def test_a_misspelt_iso_duration_is_refused_as_a_duration_not_read_as_data_fields(
        tmp_path: Path, duration: str, said: str) -> None:
    # 'PT5M5M' was read as an expression: "reads 'PT5M5M', which is not a data field ...
    # declare it: a bpmn:dataObject with id 'PT5M5M'"; 'R3/PT5M' as R3 divided by PT5M
    errors = _errors(tmp_path, TIMER.format(
        timer=f"<bpmn:timeDuration>{duration}</bpmn:timeDuration>"))
    assert len(errors) == 1, errors
    assert "damaged.bpmn:7: error: cannot read duration" in errors[0]
    assert said in errors[0]
    assert "data field" not in errors[0] and "dataObject" not in errors[0]


def test_a_flow_to_a_data_object_says_it_is_no_flow_node(tmp_path: Path) -> None:
    # it was "a bpmn:dataObject of another process or sub-process": it is in this one
    errors = _errors(tmp_path, '<bpmn:startEvent id="s"/>\n<bpmn:dataObject id="o"/>\n'
                     '<bpmn:endEvent id="e"/>\n'
                     '<bpmn:sequenceFlow id="f1" sourceRef="s" targetRef="o"/>\n'
                     '<bpmn:sequenceFlow id="f2" sourceRef="s" targetRef="e"/>\n')
    assert any("damaged.bpmn:7: error: sequence flow 'f1': targetRef 'o' is no flow node of "
               "process 'p'; it is a bpmn:dataObject (line 5), not a flow node" in e
               for e in errors), errors
    assert not any("another process" in e for e in errors), errors


def test_a_flow_into_a_sub_process_still_says_so(tmp_path: Path) -> None:
    errors = _errors(tmp_path, '<bpmn:startEvent id="s"/>\n'
                     '<bpmn:subProcess id="sub"><bpmn:task id="inner"/></bpmn:subProcess>\n'
                     '<bpmn:sequenceFlow id="f1" sourceRef="s" targetRef="inner"/>\n')
    assert any("it is a bpmn:task (line 5) of another process or sub-process" in e
               for e in errors), errors


@pytest.mark.parametrize(("declaration", "where"), [
    ('xmlns:bpmn="http://example.com/wrong"', "in namespace 'http://example.com/wrong'"),
    ('xmlns="http://www.omg.org/spec/BPMN/20100524/MODEL"', "in no namespace"),
])
def test_a_definitions_root_without_the_bpmn_namespace_says_so(
        tmp_path: Path, declaration: str, where: str) -> None:
    # was "root element is <definitions>, not an XPDL <Package> or a BPMN 2.0 <definitions>"
    path = tmp_path / "damaged.bpmn"
    prefix = "bpmn:" if declaration.startswith("xmlns:") else ""
    path.write_text('<?xml version="1.0" encoding="UTF-8"?>\n'
                    f'<{prefix}definitions {declaration if prefix else ""} id="d">\n'
                    f'<{prefix}process id="p"/>\n</{prefix}definitions>\n', encoding="utf-8")
    errors = [str(d) for d in validate_spec(path)[1].diagnostics]
    assert errors == [(f"{path}:2: error: root element <definitions> is {where}, not BPMN "
                       "2.0's, so this is no BPMN 2.0 file (nor an XPDL <Package>) (give "
                       "opspec an XPDL or a BPMN 2.0 file; if this one is BPMN, its namespace "
                       "was lost or misspelt: declare it on <definitions>, "
                       'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL")')]
