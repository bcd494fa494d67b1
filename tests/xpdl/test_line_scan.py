"""The byte scan that finds the lines of elements past 65,535 agrees with expat's count
(comments, CDATA and processing instructions holding "<" or ">", quoted ">" in attributes,
start tags spanning lines and the line where the exact count begins)."""

from __future__ import annotations

import pytest

from opspec.xpdl.read_lines import _byte_scan_lines, _expat_lines
from opspec.xpdl.reader import read_tree

NS = "http://www.wfmc.org/2008/XPDL2.1"


_BODY = (
    "<!-- a comment with <Activity Id=\"no\"/> and > in it -->",
    "<?pi <not-an-element> ?>",
    '<Activity Id="a" Name="x > y"/>',
    "<Activity\n  Id=\"b\"\n  Name='multi\nline'>",
    "<Description><![CDATA[ <Activity Id=\"cdata\"/> ]]></Description>",
    "</Activity>",
    "<Activity Id='c'\n/>",
)


def _document(padding: int) -> bytes:
    body = "\n".join(_BODY)
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="p">'
            + "\n" * padding + f"<Activities>\n{body}\n</Activities></Package>\n").encode()


@pytest.mark.parametrize("first_line", [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10])
def test_byte_scan_agrees_with_expat(first_line: int) -> None:
    for padding in (0, 3):
        data = _document(padding)
        assert _byte_scan_lines(data, first_line) == _expat_lines(data, None, first_line)


def test_lines_past_65535_are_exact() -> None:
    data = _document(70_000)
    outcome = read_tree(data, path="big.xpdl")
    lines = {element.get("Id"): line for element, line in outcome.lines.items()
             if element.get("Id")}
    assert lines == {"a": 70_005, "b": 70_009, "c": 70_013}   # the line of the closing ">"
