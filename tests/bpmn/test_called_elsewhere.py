"""A call activity into a process of another BPMN file runs that process, found as XPDL's
ExternalPackage is found and read within the same confinement — or is refused at its line.

BPMN 2.0 (OMG formal/2011-01-03, §10.2.5 Call Activity): "The Call Activity MUST fulfill the
data requirements, as well as return the data produced by the CallableElement being invoked";
its ``calledElement`` is a reference (a QName) to the CallableElement, which may be in another
file the definitions ``import`` (§8.3.3 Import: "The Import class is used when referencing
external element, either BPMN elements contained in other BPMN Definitions or non-BPMN
elements").
"""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

HEAD = ('<?xml version="1.0" encoding="UTF-8"?>\n'
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
        'xmlns:opspec="urn:opspec:sisarl:1" xmlns:st="urn:stock" id="{id}" '
        'targetNamespace="urn:{id}">\n')


def _caller(called: str, imports: str = "") -> str:
    return HEAD.format(id="order") + f"""{imports}
  <bpmn:process id="take_order" isExecutable="true">
    <bpmn:startEvent id="s"/>
    <bpmn:sequenceFlow id="f1" sourceRef="s" targetRef="call"/>
    <bpmn:callActivity id="call" name="Check stock" calledElement="{called}"/>
    <bpmn:sequenceFlow id="f2" sourceRef="call" targetRef="e"/>
    <bpmn:endEvent id="e"/>
  </bpmn:process>
</bpmn:definitions>
"""


def _callee(process: str = "check_stock", body: str = "") -> str:
    return HEAD.format(id="stock") + f"""
  <bpmn:process id="{process}" isExecutable="true">
    <bpmn:startEvent id="s2"/>
    <bpmn:sequenceFlow id="g1" sourceRef="s2" targetRef="count"/>
    <bpmn:task id="count" name="Count the shelf">
      <bpmn:extensionElements><opspec:Duration>PT3M</opspec:Duration></bpmn:extensionElements>
    </bpmn:task>{body}
    <bpmn:sequenceFlow id="g2" sourceRef="count" targetRef="e2"/>
    <bpmn:endEvent id="e2"/>
  </bpmn:process>
</bpmn:definitions>
"""


def _completions(path: Path) -> list[tuple[float, str | None, str | None]]:
    outcome = opspec.run(path, until=3600.0)
    return [(e.time, e.process, e.activity) for e in outcome.trace
            if e.kind in ("activity.completed", "process.completed")]


def _errors(path: Path) -> list[tuple[str, int | None, str]]:
    _package, report = validate_spec(path)
    return [(d.code, d.location.line, d.message) for d in report.diagnostics
            if d.severity is Severity.ERROR]


def test_a_process_in_a_bpmn_file_beside_the_diagram_is_called(tmp_path: Path) -> None:
    (tmp_path / "order.bpmn").write_text(_caller("check_stock"), encoding="utf-8")
    (tmp_path / "stock.bpmn").write_text(_callee(), encoding="utf-8")
    (tmp_path / "notes.xml").write_text("<notes/>", encoding="utf-8")   # not BPMN: skipped
    done = _completions(tmp_path / "order.bpmn")
    assert (180.0, "check_stock", "count") in done
    assert (180.0, "take_order", "call") in done and done[-1] == (180.0, "take_order", None)


def test_an_imported_file_is_read_and_a_prefixed_called_element_names_its_process(
        tmp_path: Path) -> None:
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "stock.bpmn").write_text(_callee(), encoding="utf-8")
    imports = ('  <bpmn:import importType="http://www.omg.org/spec/BPMN/20100524/MODEL" '
               'location="parts/stock.bpmn" namespace="urn:stock"/>')
    path = tmp_path / "order.bpmn"
    path.write_text(_caller("st:check_stock", imports), encoding="utf-8")
    assert not _errors(path)
    assert (180.0, "check_stock", "count") in _completions(path)


def test_an_import_leading_out_of_the_folder_is_refused_at_its_line(tmp_path: Path) -> None:
    inside = tmp_path / "model"
    inside.mkdir()
    (tmp_path / "stock.bpmn").write_text(_callee(), encoding="utf-8")
    imports = ('  <bpmn:import importType="http://www.omg.org/spec/BPMN/20100524/MODEL" '
               'location="../stock.bpmn" namespace="urn:stock"/>')
    path = inside / "order.bpmn"
    path.write_text(_caller("check_stock", imports), encoding="utf-8")
    errors = _errors(path)
    assert ("external-package-outside", 3) in {(code, line) for code, line, _m in errors}
    # and the process is not taken from the file it would have read
    assert "undefined-subflow" in {code for code, _line, _m in errors}


def test_a_process_in_no_file_is_refused_at_the_call_activitys_line(tmp_path: Path) -> None:
    (tmp_path / "stock.bpmn").write_text(_callee("another_process"), encoding="utf-8")
    path = tmp_path / "order.bpmn"
    path.write_text(_caller("check_stock"), encoding="utf-8")
    assert ("undefined-subflow", 7) in {(code, line) for code, line, _m in _errors(path)}


def test_files_calling_each_other_are_each_read_once(tmp_path: Path) -> None:
    """order.bpmn's take_order calls stock.bpmn's check_stock, which calls reorder, a process
    of order.bpmn: the call back is resolved in the file being read, not by reading it again."""
    order = _caller("check_stock").replace("</bpmn:definitions>", """
  <bpmn:process id="reorder" isExecutable="true">
    <bpmn:startEvent id="r1"/>
    <bpmn:sequenceFlow id="r2" sourceRef="r1" targetRef="r3"/>
    <bpmn:endEvent id="r3"/>
  </bpmn:process>
</bpmn:definitions>""")
    (tmp_path / "order.bpmn").write_text(order, encoding="utf-8")
    stock = _callee().replace('<bpmn:sequenceFlow id="g2" sourceRef="count" targetRef="e2"/>',
                              '<bpmn:sequenceFlow id="g2" sourceRef="count" targetRef="again"/>'
                              '<bpmn:callActivity id="again" calledElement="reorder"/>'
                              '<bpmn:sequenceFlow id="g3" sourceRef="again" targetRef="e2"/>')
    (tmp_path / "stock.bpmn").write_text(stock, encoding="utf-8")
    path = tmp_path / "order.bpmn"
    assert not _errors(path)
    done = _completions(path)
    assert (180.0, "reorder", None) in done and (180.0, "take_order", None) in done


def test_each_file_beside_the_diagram_is_searched_once(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A folder of 30 diagrams that call processes no file holds: every other file is parsed
    once to be searched for both of d00's calls (not once per call)."""
    from opspec.xpdl.bpmn import imports

    for n in range(30):
        (tmp_path / f"d{n:02}.bpmn").write_text(
            _caller(f"missing_{n}").replace('id="take_order"', f'id="p{n}"'), encoding="utf-8")
    # d00 calls two missing processes: still one parse of each other file
    (tmp_path / "d00.bpmn").write_text(_caller("missing_a").replace(
        '<bpmn:sequenceFlow id="f2" sourceRef="call" targetRef="e"/>',
        '<bpmn:sequenceFlow id="f2" sourceRef="call" targetRef="call2"/>'
        '<bpmn:callActivity id="call2" calledElement="missing_b"/>'
        '<bpmn:sequenceFlow id="f3" sourceRef="call2" targetRef="e"/>'), encoding="utf-8")
    parsed: list[Path] = []
    real = imports._parse

    def counting(path: Path) -> object:
        parsed.append(path)
        return real(path)

    monkeypatch.setattr(imports, "_parse", counting)
    errors = _errors(tmp_path / "d00.bpmn")
    assert ("undefined-subflow", 7) in {(code, line) for code, line, _m in errors}
    assert len(parsed) == len(set(parsed)) == 29
