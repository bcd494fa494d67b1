"""What the commands say of XML libxml2 cannot read: its position once, in opspec's
``file:line:`` prefix and "at column N" (lxml appended ", line 52, column 19" to libxml2's
message, which opspec printed after its own ``file:52:``), its tags written as tags; and what
``opspec check`` says of a file nested too deeply to be read or checked."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from nested_blocks import nested_blocks

from opspec.cli import main
from opspec.xpdl.loader import parse_bytes

ROOT = Path(__file__).resolve().parents[2]
HINT = "fix the XML syntax at that line (an editor with XML checking shows it)"


def _with_line_appended(source: Path, target: Path, number: int, text: str) -> Path:
    lines = source.read_text(encoding="utf-8").splitlines(keepends=True)
    lines[number - 1] = lines[number - 1].rstrip("\n") + text + "\n"
    target.write_text("".join(lines), encoding="utf-8")
    return target


def _error_line(text: str, prefix: str) -> str:
    (line,) = [x for x in text.splitlines() if x.startswith(prefix)]
    return line


@pytest.mark.parametrize("command", [["validate"], ["check"], ["show"], ["compile"],
                                     ["run", "--days", "1"]])
def test_a_mismatched_tag_is_placed_once_by_every_command(command, tmp_path, capsys) -> None:
    # the newcomer's file: <Foo> appended to line 47 of the dispenser, never closed; it said
    # "...:52: error: not well-formed XML: Opening and ending tag mismatch: Foo line 47 and
    # Application, line 52, column 19; fix ..."
    spec = _with_line_appended(ROOT / "specs" / "medication_dispenser.xpdl",
                               tmp_path / "bad1.xpdl", 47, "<Foo>")
    if command[0] == "compile":
        command = [*command, "-o", str(tmp_path / "bad1.wfs")]
    assert main([command[0], str(spec), *command[1:]]) != 0
    out = capsys.readouterr()
    said = ("not well-formed XML at column 19: Opening and ending tag mismatch: <Foo> of line "
            "47 and </Application>")
    line = _error_line(out.out + out.err, f"{spec}:52: " if command[0] != "run"
                       else f"opspec run: {spec}:52: ")
    assert line.endswith(f"{said}; {HINT}"), line
    message = line.split(f"{spec}:52: ", 1)[1]
    assert "52" not in message and message.count("column") == 1    # the position, once


def test_check_says_where_a_bpmn_file_is_not_well_formed_once(tmp_path, capsys) -> None:
    spec = _with_line_appended(ROOT / "specs" / "medication_dispenser.bpmn",
                               tmp_path / "bad.bpmn", 25, "<Foo>")
    assert main(["check", "--json", str(spec)]) == 1
    (error,) = json.loads(capsys.readouterr().out)["errors"]
    assert error["line"] == 49
    assert error["message"] == (
        "not well-formed XML at column 28: Opening and ending tag mismatch: <Foo> of line 25 "
        "and </bpmn:extensionElements>")


@pytest.mark.parametrize(("data", "line", "message"), [
    (b"<Package><oops></Package>", 1,        # opened on the line of the error: no line named
     ("not well-formed XML at column 26: Opening and ending tag mismatch: <oops> and "
      "</Package>")),
    (b"<Package>\n<a x='<'/>\n</Package>\n", 2,
     "not well-formed XML at column 7: Unescaped '<' not allowed in attributes values"),
    (b"<Package>\n<a b='1'\n c='2'\n", 3,    # cut inside a tag opened on the line before
     ("the file ends inside a tag, before the XML is complete (Couldn't find the end of the "
      "start tag <a> of line 2)")),
])
def test_the_reader_names_no_position_twice(data: bytes, line: int, message: str) -> None:
    (diagnostic,) = parse_bytes(data, path="x.xpdl").diagnostics
    assert (diagnostic.location.line, diagnostic.message) == (line, message)
    assert not re.search(rf"line {line}\b", diagnostic.message)
    assert diagnostic.message.count("column") <= 1


def _deep(tmp_path: Path, levels: int = 300) -> Path:
    # elements nested deeper than libxml2 reads (256 levels), inside an ExtendedAttribute
    lines = (ROOT / "specs" / "medication_dispenser.xpdl").read_text(
        encoding="utf-8").splitlines(keepends=True)
    at = next(n for n, x in enumerate(lines) if "<ExtendedAttributes>" in x) + 1
    lines.insert(at, "<a>" * levels + "</a>" * levels + "\n")
    spec = tmp_path / "deep.xpdl"
    spec.write_text("".join(lines), encoding="utf-8")
    return spec


def test_check_says_what_to_change_in_a_file_nested_past_the_readers_limit(
        tmp_path, capsys) -> None:
    # it ended "not checked: the file could not be read as a spec (XPDL or BPMN); fix the
    # errors listed above" of a well-formed file, and its --json left out what to change
    spec = _deep(tmp_path)
    assert main(["check", str(spec)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"{spec}:") and "nested more than 256 levels deep" in out[0]
    assert "flatten the deeply nested content" in out[0]
    assert out[-1] == (f"{spec}: not checked: the file is beyond a safety limit of the XML "
                       "reader, so it was not read; change it as the error above advises")
    assert main(["check", "--json", str(spec)]) == 1
    doc = json.loads(capsys.readouterr().out)
    assert doc["loaded"] is False        # not read
    (error,) = doc["errors"]
    assert error["code"] == "resource-limit"
    assert "nested more than 256 levels deep" in error["message"]
    assert error["hint"].startswith("XPDL needs a few dozen levels at most: flatten")


def test_check_says_a_file_with_blocks_nested_too_deeply_was_read(tmp_path, capsys) -> None:
    # the file was read (validate lists its nesting error); "could not be read" was wrong
    spec = nested_blocks(tmp_path / "blocks.xpdl", 102)
    assert main(["check", str(spec)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert "nested more than 100 blocks deep" in out[0]
    assert out[-1] == (f"{spec}: not checked: its blocks nest deeper than the check follows; "
                       "change them as the nesting error above advises")
    assert main(["check", "--json", str(spec)]) == 1
    doc = json.loads(capsys.readouterr().out)
    # read, but not checked: loaded, no process verdicts, the nesting error listed
    assert doc["loaded"] is True and doc["sound"] is False and doc["processes"] == []
    assert any("nested more than 100 blocks deep" in e["message"] for e in doc["errors"])


def test_a_byte_that_is_not_utf8_is_placed_once(tmp_path, capsys) -> None:
    # it said "...:47: warning: the file declares UTF-8 but is not valid UTF-8 (line 47:
    # byte 0xE9); ..."
    lines = (ROOT / "specs" / "medication_dispenser.xpdl").read_bytes().split(b"\n")
    lines[46] = lines[46].replace(b'"dispense"', b'"dispens\xe9"', 1)
    spec = tmp_path / "latin.xpdl"
    spec.write_bytes(b"\n".join(lines))
    main(["validate", str(spec)])
    line = _error_line(capsys.readouterr().out, f"{spec}:47: warning: ")
    message = line.split(f"{spec}:47: ", 1)[1]
    assert message.startswith("warning: the file declares UTF-8 but is not valid UTF-8 (byte "
                              "0xE9); read it as Latin-1; ")
    assert "47" not in message
