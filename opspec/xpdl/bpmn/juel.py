"""Camunda's expressions (JUEL ``${…}``, with Spin's JSON accessors) as opspec conditions.

Camunda Modeler writes conditions in the Unified Expression Language: ``${score gt 50 and
not empty name}``, ``${execution.getVariable("approved")}``, ``${customer.prop("age")
.numberValue() >= 18}``. Where such an expression is a pure read of process variables and a
comparison, it means the same as an opspec condition, and is rewritten into one token by
token (outside string literals):

======================================  ====================================
JUEL / Spin                             opspec
======================================  ====================================
``eq ne lt gt le ge``                   ``== != < > <= >=``
``and or not`` ``&& || !``              the same
``empty x``                             ``(x == null || x == "")``
``execution.getVariable("x")``          ``x``
``x.equals("a")``                       ``(x == "a")``
``S(x)``, ``x.prop("a").prop("b")``     ``x.a.b``
``.numberValue() .stringValue()``       (dropped: a value is its own value)
``.boolValue() .value()``
======================================  ====================================

Anything else — a method call with effects, ``execution`` used otherwise, ``jsonPath``,
lambda or ternary — is left as written, so the condition parser refuses it at its line
naming the construct (docs/bpmn.md, Scripts and conditions).
"""

from __future__ import annotations

import re
from collections.abc import Callable

__all__ = ["from_juel", "outside_strings"]

_OPERATORS = {"eq": "==", "ne": "!=", "lt": "<", "gt": ">", "le": "<=", "ge": ">="}
_STRING = r"""("(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*')"""
_STRINGS = re.compile(_STRING)
_GET_VARIABLE = re.compile(r"\bexecution\s*\.\s*getVariable\s*\(\s*" + _STRING + r"\s*\)")
_SPIN_WRAP = re.compile(r"\bS\s*\(\s*([A-Za-z_]\w*)\s*\)")
_PROP = re.compile(r"\s*\.\s*prop\s*\(\s*" + _STRING + r"\s*\)")
_VALUE = re.compile(r"\s*\.\s*(?:numberValue|stringValue|boolValue|value)\s*\(\s*\)")
_EQUALS = re.compile(r"([A-Za-z_][\w.]*)\s*\.\s*equals\s*\(\s*(" + _STRING[1:-1] + r"|[\w.]+)"
                     r"\s*\)")
_EMPTY = re.compile(r"\bempty\s+([A-Za-z_][\w.]*)")
_WORD = re.compile(r"\b(eq|ne|lt|gt|le|ge)\b")
_NAME = re.compile(r"^[A-Za-z_]\w*$")


def from_juel(text: str) -> str:
    """``text`` (the inside of ``${…}``) rewritten into opspec's condition grammar where it
    is a pure read and comparison; the rest is kept as written for the parser to refuse."""
    # string literals are kept whole; the rewrites apply to what lies between them, after a
    # first pass for the constructs whose arguments are string literals
    text = _GET_VARIABLE.sub(lambda m: _variable(m.group(1)) or m.group(0), text)
    text = _SPIN_WRAP.sub(r"\1", text)
    text = _PROP.sub(lambda m: _property(m.group(1)) or m.group(0), text)
    text = _VALUE.sub("", text)
    text = _EQUALS.sub(r"(\1 == \2)", text)
    return outside_strings(text, _STRINGS, _plain)


def outside_strings(text: str, strings: re.Pattern[str], rewrite: Callable[[str], str]) -> str:
    """``text`` with ``rewrite`` applied to what lies between its string literals (matches of
    ``strings``), the literals kept whole."""
    parts: list[str] = []
    last = 0
    for match in strings.finditer(text):
        parts.append(rewrite(text[last:match.start()]))
        parts.append(match.group(0))
        last = match.end()
    parts.append(rewrite(text[last:]))
    return "".join(parts)


def _plain(text: str) -> str:
    text = _EMPTY.sub(r'(\1 == null || \1 == "")', text)
    return _WORD.sub(lambda m: _OPERATORS[m.group(1)], text)


def _variable(quoted: str) -> str | None:
    name = quoted[1:-1]
    return name if _NAME.match(name) else None


def _property(quoted: str) -> str | None:
    name = quoted[1:-1]
    return f".{name}" if _NAME.match(name) else None
