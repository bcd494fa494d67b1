"""Print an expression tree back as condition text that opspec's parser reads to the same tree.

The printer lives in the model (not in :mod:`opspec.xpdl.conditions`, which re-exports it) so
that the engine can quote a condition in its error messages without importing the front end.
The output is JavaScript-like (``&&``, ``||``, ``!``, ``==``, double-quoted strings), which
the XPDL editors we know of read as well; parentheses appear only where precedence needs them.
"""

from __future__ import annotations

import math

from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary

__all__ = ["RESERVED_WORDS", "SCRIPT_WORDS", "is_identifier", "is_reserved", "to_text"]

RESERVED_WORDS = frozenset({"and", "or", "not", "true", "false", "null"})
"""Words (compared case-insensitively) that cannot start a data-field name; ``None`` (exactly
so spelled, Python's null) is reserved as well."""

SCRIPT_WORDS = frozenset({"var", "let", "const", "new", "function", "return", "if", "else"})
"""Words (case-sensitive) that start a script statement; the parser refuses them as names."""

# Binding power of each operator; higher binds tighter. The parser uses the same numbers.
PRECEDENCE: dict[str, int] = {
    "or": 1,
    "and": 2,
    "==": 4, "!=": 4,
    "<": 5, "<=": 5, ">": 5, ">=": 5,
    "+": 6, "-": 6,
    "*": 7, "/": 7, "%": 7,
}
_PREFIX = 8
_ATOM = 10
_SPELLING = {"and": "&&", "or": "||"}
_COMPARISONS = frozenset({"==", "!=", "<", "<=", ">", ">="})
_ESCAPES = {'"': '\\"', "\\": "\\\\", "\n": "\\n", "\r": "\\r", "\t": "\\t"}


def is_identifier(word: str) -> bool:
    """Whether ``word`` is one name part the parser reads as a name (letters, digits, ``_``,
    ``$``; not starting with a digit)."""
    if not word or not (word[0].isalpha() or word[0] in "_$"):
        return False
    return all(ch.isalnum() or ch in "_$" for ch in word[1:])


def is_reserved(word: str) -> bool:
    """Whether ``word`` is a keyword rather than a name at the start of a value."""
    return word.lower() in RESERVED_WORDS or word == "None" or word in SCRIPT_WORDS


def to_text(expr: Expression) -> str:
    """Condition text for ``expr``; ``parse_expression(to_text(e)) == e`` for every tree the
    parser can produce.

    Raises ``ValueError`` for trees no text can express: a NaN literal, a name part that is not
    an identifier, or a name starting with a reserved word (``true``, ``and``...).
    """
    return _text(expr)[0]


def _text(expr: Expression) -> tuple[str, int]:
    """The text of ``expr`` and the binding power of its outermost operator."""
    if isinstance(expr, Literal):
        return _literal(expr.value), _ATOM
    if isinstance(expr, Name):
        for i, part in enumerate(expr.path):
            if not is_identifier(part) or (i == 0 and is_reserved(part)):
                raise ValueError(f"name {'.'.join(expr.path)!r} cannot be written as text")
        if not expr.path:
            raise ValueError("a name needs at least one part")
        return ".".join(expr.path), _ATOM
    if isinstance(expr, Call):
        args = ", ".join(_text(arg)[0] for arg in expr.args)
        return f"{expr.function}({args})", _ATOM
    if isinstance(expr, Unary):
        operand, power = _text(expr.operand)
        symbol = {"not": "!", "neg": "-"}.get(expr.op)
        if symbol is None:
            raise ValueError(f"unknown unary operator {expr.op!r}")
        # "-(1)" keeps a negated literal a Unary node (the parser folds "-1" to Literal(-1)).
        wrap = power < _PREFIX or (
            expr.op == "neg" and isinstance(expr.operand, (Literal, Unary))
        )
        return f"{symbol}({operand})" if wrap else f"{symbol}{operand}", _PREFIX
    if isinstance(expr, Binary):
        op_power = PRECEDENCE.get(expr.op)
        if op_power is None:
            raise ValueError(f"unknown binary operator {expr.op!r}")
        left, left_power = _text(expr.left)
        right, right_power = _text(expr.right)
        # Comparisons never chain in printed text: the parser reads "a < b < c" as a range.
        if left_power < op_power or (left_power == op_power and expr.op in _COMPARISONS):
            left = f"({left})"
        if right_power <= op_power:
            right = f"({right})"
        return f"{left} {_SPELLING.get(expr.op, expr.op)} {right}", op_power
    raise ValueError(f"not an expression node: {expr!r}")


def _literal(value: object) -> str:
    if value is None:
        return "null"
    if value is True:
        return "true"
    if value is False:
        return "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            raise ValueError("NaN cannot be written as a condition literal")
        if math.isinf(value):
            return "1e999" if value > 0 else "-1e999"
        return repr(value)
    if isinstance(value, str):
        out = []
        for ch in value:
            if ch in _ESCAPES:
                out.append(_ESCAPES[ch])
            elif ord(ch) < 0x20 or ord(ch) == 0x7F:
                out.append(f"\\u{ord(ch):04x}")
            else:
                out.append(ch)
        return '"' + "".join(out) + '"'
    raise ValueError(f"literal of unsupported type {type(value).__name__}: {value!r}")
