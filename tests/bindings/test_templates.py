"""Line templates: one syntax to build commands and to read replies."""

from __future__ import annotations

import pytest

from opspec.bindings.templates import LineTemplate, TemplateError


def test_fill_formats_typed_placeholders() -> None:
    assert LineTemplate.parse("MOTOR {left:int} {right:int}").fill(
        {"left": "50", "right": -20}) == "MOTOR 50 -20"


def test_match_returns_typed_values_or_none() -> None:
    template = LineTemplate.parse("RANGE {distance:float} {unit}")
    assert template.match("RANGE 12.5 cm") == {"distance": 12.5, "unit": "cm"}
    assert template.match("RANGE far cm") is None
    assert template.match("XRANGE 1 cm") is None


def test_bool_placeholders_read_device_words_and_send_1_or_0() -> None:
    template = LineTemplate.parse("BUMP {bump:bool}")
    assert [template.match(f"BUMP {w}") for w in ("1", "0", "TRUE", "off", "yes")] == [
        {"bump": True}, {"bump": False}, {"bump": True}, {"bump": False}, {"bump": True}]
    assert template.match("BUMP maybe") is None
    assert template.fill({"bump": True}) == "BUMP 1"
    assert template.fill({"bump": "false"}) == "BUMP 0"
    with pytest.raises(TemplateError, match="not bool"):
        template.fill({"bump": 7})


def test_literal_braces_are_doubled() -> None:
    template = LineTemplate.parse("SET {{mode}} {value:int}")
    assert template.fill({"value": 3}) == "SET {mode} 3"
    assert template.match("SET {mode} 3") == {"value": 3}


def test_regex_characters_in_literals_are_literal() -> None:
    assert LineTemplate.parse("RANGE?").match("RANGE?") == {}
    assert LineTemplate.parse("RANGE?").match("RANG") is None


@pytest.mark.parametrize(("text", "words"), [
    ("DISPENSE {slot", "unbalanced"),
    ("DISPENSE slot}", "unbalanced"),
    ("DISPENSE {}", "needs a name"),
    ("DISPENSE {slot:hex}", "unknown type 'hex'"),
    ("{a} {a}", "appears twice"),
], ids=["open-brace", "close-brace", "no-name", "unknown-type", "duplicate"])
def test_malformed_templates_are_explained(text: str, words: str) -> None:
    with pytest.raises(TemplateError, match=words):
        LineTemplate.parse(text)


def test_fill_refuses_missing_wrongly_typed_or_multiline_values() -> None:
    template = LineTemplate.parse("DISPENSE {slot:int}")
    with pytest.raises(TemplateError, match="needs a value for {slot}"):
        template.fill({})
    with pytest.raises(TemplateError, match="not int"):
        template.fill({"slot": "two"})
    with pytest.raises(TemplateError, match="line break"):
        LineTemplate.parse("SAY {text}").fill({"text": "a\nb"})
