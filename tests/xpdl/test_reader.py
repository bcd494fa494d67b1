"""The hardened reader: hostile and malformed input gives one clean error naming file:line."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

from opspec.errors import Severity
from opspec.model import XpdlVersion
from opspec.xpdl import XmlReadError, load_package, parse_bytes, read_xml
from opspec.xpdl.reader import line_of, read_limited

DATA = Path(__file__).parent / "data"

MINIMAL = b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p"/>'


@pytest.mark.parametrize(
    ("name", "code", "line"),
    [
        ("xxe.xpdl", "doctype", 2),
        ("billion_laughs.xpdl", "doctype", 2),
        ("external_dtd.xpdl", "doctype", 2),
        ("garbage.xpdl", "not-a-spec", 1),       # a PNG: said to be a binary file
        ("truncated.xpdl", "not-well-formed", 6),
        ("empty.xpdl", "empty-file", 1),
        ("wrong_root.xpdl", "unknown-root", 2),
        ("unknown_namespace.xpdl", "unknown-version", 2),
    ],
    ids=lambda value: str(value),
)
def test_hostile_or_broken_file_is_rejected_with_one_located_error(
    name: str, code: str, line: int | None
) -> None:
    result = load_package(DATA / name)
    assert result.package is None
    assert not result.ok
    assert [d.code for d in result.diagnostics] == [code]
    diagnostic = result.diagnostics[0]
    assert diagnostic.severity is Severity.ERROR
    assert diagnostic.location.path.endswith(name)
    if line is not None:
        assert diagnostic.location.line is not None and diagnostic.location.line >= line
    assert "\n" not in str(diagnostic)


def test_xxe_never_leaks_local_files() -> None:
    result = load_package(DATA / "xxe.xpdl")
    assert "root:" not in "".join(str(d) for d in result.diagnostics)
    assert "DOCTYPE" in result.diagnostics[0].message


def test_doctype_message_says_how_to_fix() -> None:
    with pytest.raises(XmlReadError, match="DOCTYPE declarations are not allowed") as info:
        read_xml((DATA / "external_dtd.xpdl").read_bytes(), path="x.xpdl")
    assert info.value.code == "doctype"
    assert "remove the <!DOCTYPE" in str(info.value)


@pytest.mark.parametrize("encoding", ["utf-8", "utf-16"])
@pytest.mark.parametrize("doctype", [
    '<!DOCTYPE Package SYSTEM "http://example.org/x.dtd">',            # parses: docinfo check
    '<!DOCTYPE Package [<!ENTITY e SYSTEM "file:///etc/passwd">]>',    # parses
    '<!DOCTYPE Package [<!ENTITY broken',                               # does not parse
], ids=["external", "entity", "broken"])
def test_doctype_error_names_the_doctype_line(doctype: str, encoding: str) -> None:
    text = ('<?xml version="1.0"?>\n<!-- a comment\nover two lines -->\n' + doctype
            + '\n<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p"/>\n')
    result = parse_bytes(text.encode(encoding), path="d.xpdl")
    (diagnostic,) = result.diagnostics
    assert diagnostic.code == "doctype"
    assert diagnostic.location.line == 4


def test_file_over_the_size_limit_is_refused_before_parsing(tmp_path: Path) -> None:
    big = tmp_path / "big.xpdl"
    big.write_bytes(MINIMAL + b" " * 5000)
    result = load_package(big, max_bytes=1000)
    assert result.package is None
    assert result.diagnostics[0].code == "too-big"
    assert "1,000 bytes" in result.diagnostics[0].message


def test_size_limit_hint_names_the_variable_that_raises_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from opspec.xpdl.reader import DEFAULT_MAX_BYTES, MAX_BYTES_VARIABLE

    big = tmp_path / "big.xpdl"
    big.write_bytes(MINIMAL + b" " * 5000)
    monkeypatch.setenv(MAX_BYTES_VARIABLE, "1000")
    (diagnostic,) = load_package(big).diagnostics     # the default limit, replaced by the variable
    assert diagnostic.code == "too-big" and diagnostic.location.line == 1
    assert MAX_BYTES_VARIABLE in diagnostic.hint and "1,000 bytes" in diagnostic.message
    assert parse_bytes(big.read_bytes(), path="big.xpdl").diagnostics[0].code == "too-big"
    monkeypatch.setenv(MAX_BYTES_VARIABLE, "100000")
    assert load_package(big).ok
    # an explicit max_bytes from a caller wins over the variable
    assert load_package(big, max_bytes=1000).diagnostics[0].code == "too-big"
    assert DEFAULT_MAX_BYTES > 100000


@pytest.mark.parametrize("value", ["lots", "-5", "0"])
def test_a_bad_size_limit_setting_is_an_error_not_ignored(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, value: str
) -> None:
    from opspec.xpdl.reader import MAX_BYTES_VARIABLE

    spec = tmp_path / "ok.xpdl"
    spec.write_bytes(MINIMAL)
    monkeypatch.setenv(MAX_BYTES_VARIABLE, value)
    (diagnostic,) = load_package(spec).diagnostics
    assert diagnostic.code == "bad-setting" and MAX_BYTES_VARIABLE in diagnostic.message
    assert diagnostic.location.line == 1


class EndlessStream(io.RawIOBase):
    """A stream that never ends (like /dev/zero); counts what was read."""

    def __init__(self) -> None:
        self.delivered = 0

    def readable(self) -> bool:
        return True

    def read(self, size: int = -1) -> bytes:
        size = 65536 if size is None or size < 0 else size
        self.delivered += size
        return b"<" * size


def test_endless_stream_is_cut_off_just_past_the_limit() -> None:
    stream = EndlessStream()
    with pytest.raises(XmlReadError, match="larger than the limit") as info:
        read_limited(stream, path="endless", max_bytes=100_000)  # type: ignore[arg-type]
    assert info.value.code == "too-big"
    assert stream.delivered <= 100_001 + 1024 * 1024


def test_bytes_over_the_limit_are_refused() -> None:
    result = parse_bytes(MINIMAL + b" " * 100, path="mem.xpdl", max_bytes=50)
    assert [d.code for d in result.diagnostics] == ["too-big"]


def test_missing_file_is_an_io_error_not_a_traceback(tmp_path: Path) -> None:
    result = load_package(tmp_path / "nope.xpdl")
    assert result.package is None
    assert result.diagnostics[0].code == "io-error"


@pytest.mark.parametrize(
    ("namespace", "version"),
    [
        ("http://www.wfmc.org/2002/XPDL1.0", XpdlVersion.V1_0),
        ("http://www.wfmc.org/2004/XPDL2.0alpha", XpdlVersion.V2_0),
        ("http://www.wfmc.org/2008/XPDL2.1", XpdlVersion.V2_1),
        ("http://www.wfmc.org/2009/XPDL2.2", XpdlVersion.V2_2),
        ("", XpdlVersion.NONE),
    ],
    ids=["1.0", "2.0", "2.1", "2.2", "none"],
)
def test_version_comes_from_root_namespace_not_xpdlversion(
    namespace: str, version: XpdlVersion
) -> None:
    xmlns = f' xmlns="{namespace}"' if namespace else ""
    data = (f'<Package{xmlns} Id="p"><PackageHeader><XPDLVersion>2.2</XPDLVersion>'
            "</PackageHeader></Package>").encode()
    _, got = read_xml(data, path="v.xpdl")
    assert got is version


@pytest.mark.parametrize(
    "data",
    [
        b"\xef\xbb\xbf" + MINIMAL,
        '<?xml version="1.0" encoding="UTF-16"?>'.encode("utf-16") + MINIMAL.decode().encode("utf-16")[2:],
        MINIMAL,
        b'<?xml version="1.0" encoding="ASCII"?>' + MINIMAL.replace(b'Id="p"', 'Id="p" Name="caf\u00e9"'.encode()),
        b'<?xml version="1.0" encoding="us-ascii"?>' + MINIMAL,
    ],
    ids=["utf8-bom", "utf16-bom", "no-declaration", "ascii-declared-utf8-content", "us-ascii"],
)
def test_encodings_found_in_real_files_are_read(data: bytes) -> None:
    result = parse_bytes(data, path="enc.xpdl")
    assert result.package is not None, result.diagnostics
    assert result.package.id == "p"


def test_ascii_declared_file_keeps_utf8_text() -> None:
    data = b'<?xml version="1.0" encoding="ASCII"?>' + MINIMAL.replace(
        b'Id="p"', 'Id="p" Name="caf\u00e9"'.encode())
    result = parse_bytes(data, path="enc.xpdl")
    assert result.package is not None and result.package.name == "caf\u00e9"


def test_latin1_file_without_declaration_is_read_with_a_warning() -> None:
    data = MINIMAL.replace(b'Id="p"', 'Id="p" Name="caf\u00e9"'.encode("latin-1"))
    result = parse_bytes(data, path="latin.xpdl")
    assert result.package is not None and result.package.name == "caf\u00e9"
    assert [d.code for d in result.diagnostics] == ["encoding-guessed"]


def test_line_numbers_past_65535_are_unknown_outside_a_build() -> None:
    # inside a build the reader's own count gives them (tests/xpdl/test_hostile_input.py)
    data = b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">' + b"\n" * 70000 + b"<X/></Package>"
    root, _ = read_xml(data, path="long.xpdl")
    assert line_of(root) == 1
    assert line_of(root[0]) is None


def test_deeply_nested_input_is_refused_not_a_crash() -> None:
    data = b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">' + b"<a>" * 100_000
    result = parse_bytes(data, path="deep.xpdl")
    assert result.package is None
    assert result.diagnostics[0].code == "resource-limit"


WELL_FORMED_BUT_TOO_MUCH = {
    "deep-extended-attribute": (
        b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">\n<ExtendedAttributes>'
        b'<ExtendedAttribute Name="x">' + b"<a>" * 2000 + b"</a>" * 2000
        + b"</ExtendedAttribute></ExtendedAttributes></Package>", "nested more than 256"),
    "huge-attribute-value": (
        b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p" Name="'
        + b"x" * 10_000_100 + b'"/>', "longer than"),
    "huge-text-node": (
        b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p"><Description>'
        + b"x" * 10_000_100 + b"</Description></Package>", "longer than"),
}


@pytest.mark.parametrize("case", sorted(WELL_FORMED_BUT_TOO_MUCH))
def test_reader_limits_give_their_own_one_line_message_with_a_usable_hint(case: str) -> None:
    data, says = WELL_FORMED_BUT_TOO_MUCH[case]
    result = parse_bytes(data, path="big.xpdl")
    assert result.package is None
    (diagnostic,) = result.diagnostics
    assert diagnostic.code == "resource-limit"
    assert says in diagnostic.message
    assert diagnostic.location.line is not None
    text = str(diagnostic)
    assert "\n" not in text
    # the user can neither pass XML_PARSE_HUGE nor "fix the syntax" of a well-formed file
    assert "XML_PARSE_HUGE" not in text and "syntax" not in text
    assert diagnostic.hint


DISPENSER = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


@pytest.mark.parametrize("newline", [True, False], ids=["ends-with-newline", "cut-mid-line"])
def test_a_file_cut_short_is_said_to_end_early_at_its_last_line(newline: bool) -> None:
    # `head -205 dispenser.xpdl` was "trunc.xpdl:206: ... Premature end of data ...; fix the
    # XML syntax at that line": a line the file does not have, and nothing there to fix.
    lines = DISPENSER.read_bytes().splitlines(keepends=True)[:205]
    data = b"".join(lines) if newline else b"".join(lines).rstrip(b"\n")
    diagnostic = parse_bytes(data, path="trunc.xpdl").diagnostics[0]
    assert diagnostic.code == "not-well-formed"
    assert str(diagnostic) == (
        "trunc.xpdl:205: error: the file ends before the XML is complete (<Activity>, opened "
        "at line 202, is not closed); the file may have been cut short: restore its end (from "
        "a copy, or from the tool that wrote it)")


@pytest.mark.parametrize(("data", "line", "what"), [
    (b"<Package>\n<!-- a note\n", 2, "a comment is not closed with -->"),
    (b"<Package>\n<![CDATA[ x\n", 2, "a CDATA section is not closed with ]]>"),
    (b"<Package><A>text", 1, "<A>, opened at line 1, is not closed"),
])
def test_what_a_file_cut_short_leaves_open_is_named(data: bytes, line: int, what: str) -> None:
    diagnostic = parse_bytes(data, path="cut.xpdl").diagnostics[0]
    assert diagnostic.location.line == line
    assert diagnostic.message == f"the file ends before the XML is complete ({what})"


@pytest.mark.parametrize("data", [b"<Package><oops></Package>",
                                  b"<Package>\n<oops>\n</Package>"])
def test_a_mismatched_end_tag_at_the_end_is_a_syntax_error_not_a_cut(data: bytes) -> None:
    diagnostic = parse_bytes(data, path="x.xpdl").diagnostics[0]
    assert re.match(r"not well-formed XML at column \d+: Opening and ending tag mismatch: "
                    r"<oops>( of line 2)? and </Package>$", diagnostic.message)


def test_a_syntax_error_inside_the_file_still_says_fix_the_syntax() -> None:
    diagnostic = parse_bytes(b"<Package>\n<a b=1/>\n</Package>\n", path="x.xpdl").diagnostics[0]
    assert diagnostic.location.line == 2
    assert diagnostic.message == "not well-formed XML at column 6: AttValue: \" or ' expected"
    assert diagnostic.hint.startswith("fix the XML syntax at that line")


def test_not_well_formed_messages_are_one_line() -> None:
    result = parse_bytes(b'<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">\n<a',
                         path="cut.xpdl")
    assert result.diagnostics[0].code == "not-well-formed"
    assert "\n" not in str(result.diagnostics[0])


@pytest.mark.parametrize(("data", "line"), [
    (b"<Package>\n  <Activity Id=\"a\"><Impleme\n", 2),          # cut inside a tag
    (b"<Package>\n  <Activity Id=\"a\"><Applicatio", 2),        # ... without a newline
    ((DATA / "truncated.xpdl").read_bytes(), 6),
])
def test_a_file_cut_inside_a_tag_ends_at_its_last_line_not_past_it(data: bytes,
                                                                    line: int) -> None:
    # libxml2 looks past the end for the '>' it still needs, and placed the error there
    # (truncated.xpdl:7 of a 6-line file)
    diagnostic = parse_bytes(data, path="cut.xpdl").diagnostics[0]
    assert diagnostic.code == "not-well-formed" and diagnostic.location.line == line
    assert diagnostic.message.startswith("the file ends inside a tag, before the XML is "
                                         "complete (")
    assert "line" not in diagnostic.message             # no position past the file's end
    assert "column" not in diagnostic.message
    assert diagnostic.hint.startswith("the file may have been cut short")
