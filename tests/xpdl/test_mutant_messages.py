"""What the mutation harness (benchmarks/mutation_fuzz.py) found in damaged XPDL files: each
message is true of the file and names its line, and validate refuses what run refuses."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

CAUGHT = ('<Activity Id="b"><Implementation><No/></Implementation></Activity>\n',
          ('<Transition Id="t" From="a" To="b"><Condition Type="EXCEPTION">late</Condition>'
           '</Transition>'))


def _spec(tmp_path: Path, activities: str, transitions: str = "") -> Path:
    path = tmp_path / "damaged.xpdl"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="pkg">\n'
        '<WorkflowProcesses><WorkflowProcess Id="p">\n'
        f'<Activities>\n{activities}</Activities>\n'
        f'<Transitions>{transitions}</Transitions>\n'
        '</WorkflowProcess></WorkflowProcesses>\n</Package>\n', encoding="utf-8")
    return path


def _errors(path: Path) -> list[str]:
    return [str(d) for d in validate_spec(path)[1].diagnostics if d.severity is Severity.ERROR]


@pytest.mark.parametrize(("duration", "said"), [
    ("PT5M5M", "cannot read duration 'PT5M5M'"),
    ("P1DT", "cannot read duration 'P1DT'"),
    ("R3/PT5M", "it is a repeating interval (a cycle), not a duration"),
])
def test_a_misspelt_iso_deadline_is_refused_as_a_duration_not_read_as_data_fields(
        tmp_path: Path, duration: str, said: str) -> None:
    # 'PT5M5M' was "a deadline of activity 'a' reads 'PT5M5M', which is not a data field"
    path = _spec(tmp_path, '<Activity Id="a"><Implementation><No/></Implementation>\n'
                 '<Deadline Execution="SYNCHR">\n'
                 f'<DeadlineDuration>{duration}</DeadlineDuration>\n'
                 '<ExceptionName>late</ExceptionName></Deadline></Activity>\n' + CAUGHT[0],
                 CAUGHT[1])
    errors = _errors(path)
    assert len(errors) == 1, errors
    assert errors[0].startswith(f"{path}:7: error: Deadline: cannot read duration"), errors
    assert said in errors[0] and "which is not a data field" not in errors[0]


def test_a_deadline_reading_a_data_field_is_still_an_expression(tmp_path: Path) -> None:
    # a name that only looks like a unit-less ISO duration ('P1') is a data field's
    path = _spec(tmp_path, '<Activity Id="a"><Implementation><No/></Implementation>\n'
                 '<Deadline Execution="SYNCHR">\n'
                 '<DeadlineDuration>P1</DeadlineDuration>\n'
                 '<ExceptionName>late</ExceptionName></Deadline></Activity>\n' + CAUGHT[0],
                 CAUGHT[1])
    errors = _errors(path)
    assert any("reads 'P1', which is not a data field" in e for e in errors), errors


SMALL = ('<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="pkg"><WorkflowProcesses>'
         '<WorkflowProcess Id="p" Name="Caf\xe9"><Activities><Activity Id="a"><Implementation>'
         '<No/></Implementation></Activity></Activities></WorkflowProcess></WorkflowProcesses>'
         '</Package>\n')


@pytest.mark.parametrize(("declared", "said"), [
    ("bogus-8", ("the XML declaration names encoding 'bogus-8', which is no encoding "
                 "opspec knows")),
    ("UTF-16", "the XML declaration says UTF-16, but the file is 8-bit text"),
    ("UTF-32", "the XML declaration says UTF-32, but the file is 8-bit text"),
])
def test_an_impossible_encoding_declaration_is_said_at_its_line(
        tmp_path: Path, declared: str, said: str) -> None:
    # were "not well-formed XML at column 39: Unsupported encoding" / "Blank needed here" with
    # "fix the XML syntax at that line", and with one Latin-1 byte "a binary file (not text)"
    for body in (SMALL.replace("\xe9", "e").encode(), SMALL.encode("latin-1")):
        path = tmp_path / "damaged.xpdl"
        path.write_bytes(f'<?xml version="1.0" encoding="{declared}"?>\n'.encode() + body)
        errors = _errors(path)
        assert errors == [f"{path}:1: error: {said}" + errors[0].split(said, 1)[1]], errors
        assert "binary" not in errors[0] and "XML syntax" not in errors[0]


def test_a_broken_latin_1_file_is_broken_xml_not_a_binary_file(tmp_path: Path) -> None:
    path = tmp_path / "damaged.xpdl"
    path.write_bytes(b'<?xml version="1.0" encoding="ISO-8859-1"?>\n'
                     + SMALL.encode("latin-1")[:150])
    errors = _errors(path)
    assert len(errors) == 1 and "binary" not in errors[0], errors
    assert errors[0].startswith(f"{path}:2: error: the file ends"), errors


@pytest.mark.parametrize(("timer", "said"), [
    ("1e999", "(cannot read duration '1e999': the number is too large)"),
    ("PT5M5M", "(cannot read duration 'PT5M5M': not a duration)"),
])
def test_an_unreadable_timer_says_why(tmp_path: Path, timer: str, said: str) -> None:
    # was only "timer '1e999' is not a duration, date or cycle opspec understands"
    path = _spec(tmp_path, '<Activity Id="a"><Event><IntermediateEvent Trigger="Timer">\n'
                 f'<TriggerTimer><TimeCycle>{timer}</TimeCycle></TriggerTimer>\n'
                 '</IntermediateEvent></Event></Activity>\n')
    errors = _errors(path)
    assert errors == [f"{path}:6: error: timer {timer!r} is not a duration, date or cycle "
                      f"opspec understands {said}, so the spec cannot run" + errors[0].split(
                          "so the spec cannot run", 1)[1]], errors
