"""A profile with a typo is refused at ``file:line: key``: the line the key is written on
(or its table's, for a key that is missing), so an editor jumps to it."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.bindings.profile_lines import key_line
from opspec.bindings.profiles import load_profile
from opspec.errors import BindingError

from .conftest import DEVICES

SHIPPED = (DEVICES / "medication_dispenser.toml").read_text(encoding="utf-8")


def _line_of(text: str, written: str) -> int:
    """The 1-based line holding ``written`` (once)."""
    numbers = [n for n, line in enumerate(text.splitlines(), start=1) if written in line]
    assert len(numbers) == 1, numbers
    return numbers[0]


@pytest.mark.parametrize(("typo", "fixed", "key"), [
    ("baudrat = 115200", "baudrate = 115200", "serial.baudrat"),
    ('baudrate = "fast"', "baudrate = 115200", "serial.baudrate"),
    ("[operation.dispense]", "[operations.dispense]", "operation"),
    ('command = "DISPENSE {slot:itn}"', 'command = "DISPENSE {slot:int}"',
     "operations.dispense.command"),
    ('then = "abrot"', 'then = "abort"', "fallback.dispenser.then"),
    ('"ERR JAM" = "Drawer Jammed"', '"ERR JAM" = "DrawerJammed"', "errors.ERR JAM"),
    ('emulate = { reply = 5 }', 'emulate = { reply = "OK DISPENSED {slot:int}" }',
     "operations.dispense.emulate"),
])
def test_a_typo_in_the_shipped_profile_is_refused_at_its_line(
        tmp_path: Path, typo: str, fixed: str, key: str) -> None:
    assert fixed in SHIPPED
    text = SHIPPED.replace(fixed, typo, 1)
    path = tmp_path / "medication_dispenser.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(BindingError) as refused:
        load_profile(path)
    assert refused.value.location is not None
    assert refused.value.location.line == _line_of(text, typo)
    assert str(refused.value).startswith(f"{path}:{_line_of(text, typo)}: {key}")


def test_a_missing_key_of_a_table_is_placed_at_the_table(tmp_path: Path) -> None:
    text = SHIPPED.replace('line = "BUTTON REPORT"\n', "", 1)
    path = tmp_path / "medication_dispenser.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(BindingError) as refused:
        load_profile(path)
    assert str(refused.value).startswith(
        f"{path}:{_line_of(text, '[events.report]')}: events.report.line: required key")


def test_a_missing_top_level_key_has_no_line(tmp_path: Path) -> None:
    path = tmp_path / "p.toml"
    path.write_text('participants = ["alarm"]\n[operations.alarm_on]\ncommand = "ON"\n',
                    encoding="utf-8")
    with pytest.raises(BindingError) as refused:
        load_profile(path)
    assert str(refused.value).startswith(f"{path}: format: required key is missing")


def test_key_line_reads_quoted_dotted_and_nested_keys() -> None:
    lines = [
        "format = 1",                                   # 1
        "[errors]",                                     # 2
        "'ERR {reason}' = 'DeviceError'",               # 3
        "[operations.go]",                              # 4
        'command = """GO',                              # 5
        'then = 1"""',                                  # 6: inside the string
        "port.url = 'x'  # a dotted key",               # 7
        "then = 2",                                     # 8
    ]
    text = "\n".join(lines)
    assert key_line(text, "format") == 1
    assert key_line(text, "errors.ERR {reason}") == 3
    assert key_line(text, "operations") == 4
    assert key_line(text, "operations.go.command") == 5
    assert key_line(text, "operations.go.then") == 8
    assert key_line(text, "operations.go.port.url") == 7
    assert key_line(text, "operations.go.missing") == 4
    assert key_line(text, "participants") is None


def test_a_syntax_error_is_placed_at_its_line(tmp_path: Path) -> None:
    path = tmp_path / "board.toml"
    path.write_text('format = 1\nparticipants = ["alarm"]\nx = = 3\n', encoding="utf-8")
    with pytest.raises(BindingError) as refused:
        load_profile(path)
    assert str(refused.value).startswith(f"{path}:3: not valid TOML: ")


def test_a_syntax_error_at_the_end_of_the_file_has_no_line(tmp_path: Path) -> None:
    path = tmp_path / "board.toml"
    path.write_text('format = 1\nparticipants = ["alarm"\n', encoding="utf-8")
    with pytest.raises(BindingError) as refused:
        load_profile(path)
    assert str(refused.value).startswith(f"{path}: not valid TOML: ")


def test_a_profile_saved_with_a_byte_order_mark_is_placed_at_its_line(tmp_path: Path) -> None:
    # editors on Windows save UTF-8 with a BOM; the profile is read past it, and a key on the
    # first line is still found there (the scanner read the BOM as part of the key)
    text = 'fromat = "opspec-device-profile"\n' + SHIPPED
    path = tmp_path / "medication_dispenser.toml"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    with pytest.raises(BindingError) as refused:
        load_profile(path)
    assert str(refused.value).startswith(f"{path}:1: fromat")
