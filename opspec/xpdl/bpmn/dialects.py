"""Conditions as modellers other than Camunda write them, read where they are plain reads.

BPMN's default expression language is XPath 1.0 (BPMN 2.0 §8.3.4, ``expressionLanguage``
of ``definitions``), whose data access functions are BPMN's own (§10.3.2:
``getDataObject('name')``, ``getDataInput``, ``getDataOutput``, ``getProcessProperty``,
``getActivityProperty('activity', 'name')``); FEEL-based tools (Camunda 8, Trisotech) mark an
expression with a leading ``=``; many modellers let people refer to a data object by the
name they gave it, spaces and all (``Vacation Approval = "Approved"``, ``[Service Level]``).
This module rewrites those forms into opspec's condition grammar by naming the data field
itself (by id); everything else is left as written for the condition parser to refuse at its
line.
"""

from __future__ import annotations

import re

__all__ = ["from_dialects"]

_STRING = r"""("(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*')"""
_STRINGS = re.compile(_STRING)
_DATA_ACCESS = re.compile(
    r"\b(?:bpmn:)?get(?:DataObject|DataInput|DataOutput|ProcessProperty)\s*\(\s*"
    + _STRING + r"\s*\)"
    r"|\b(?:bpmn:)?getActivityProperty\s*\(\s*" + _STRING + r"\s*,\s*" + _STRING + r"\s*\)")
_BOOLEANS = re.compile(r"\b(true|false)\s*\(\s*\)")
_BRACKETED = re.compile(r"\[([^\[\]\"']+)\]")


def from_dialects(text: str, names: dict[str, str]) -> str:
    """``text`` with XPath data access, a FEEL ``=`` marker and data objects named by their
    names (``names``: name -> data field id) rewritten as plain reads of the field."""
    stripped = text.lstrip()
    if stripped.startswith("=") and not stripped.startswith("=="):
        text = stripped[1:].lstrip()                 # FEEL's expression marker
    text = _DATA_ACCESS.sub(lambda m: _field(m, names), text)
    text = _BOOLEANS.sub(r"\1", text)
    if not names:
        return text
    spaced = sorted((n for n in names if " " in n.strip()), key=len, reverse=True)
    parts: list[str] = []
    last = 0
    for match in _STRINGS.finditer(text):
        parts.append(_names(text[last:match.start()], names, spaced))
        parts.append(match.group(0))
        last = match.end()
    parts.append(_names(text[last:], names, spaced))
    return "".join(parts)


_IDENTIFIER = re.compile(r"[A-Za-z_]\w*")


def _field(match: re.Match[str], names: dict[str, str]) -> str:
    quoted = match.group(1) or match.group(3)
    name = quoted[1:-1].strip()
    field = names.get(name, name)
    if _IDENTIFIER.fullmatch(field):
        return field
    # an id an expression cannot name (a UUID with hyphens): the name the modeller gave it,
    # when that is one
    return name if _IDENTIFIER.fullmatch(name) else match.group(0)


def _names(text: str, names: dict[str, str], spaced: list[str]) -> str:
    text = _BRACKETED.sub(lambda m: _nameable(names.get(m.group(1).strip())) or m.group(0),
                          text)
    for name in spaced:
        field = _nameable(names[name])
        if field is not None:
            pattern = r"(?<![\w.])" + r"\s+".join(map(re.escape, name.split())) + r"(?![\w(])"
            text = re.sub(pattern, field, text)
    return text


def _nameable(field: str | None) -> str | None:
    return field if field is not None and _IDENTIFIER.fullmatch(field) else None
