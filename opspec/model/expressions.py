"""Expression trees for XPDL conditions, deadlines and assignments.

Conditions in real XPDL files are written in JavaScript-ish or Java-ish text
(``n < 3 && !done``, ``status == "ok"``, ``x = 'y'``). The front end parses them once, at load
time, into these immutable nodes; the engine evaluates the nodes against data fields. Nothing
is ever passed to ``eval``.

Operators are spelled canonically whatever the source wrote: ``and``, ``or``, ``not``, ``neg``,
``==``, ``!=``, ``<``, ``<=``, ``>``, ``>=``, ``+``, ``-``, ``*``, ``/``, ``%``.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "BINARY_OPERATORS",
    "UNARY_OPERATORS",
    "Binary",
    "Call",
    "Expression",
    "Literal",
    "Name",
    "Unary",
]

UNARY_OPERATORS = frozenset({"not", "neg"})
BINARY_OPERATORS = frozenset(
    {"and", "or", "==", "!=", "<", "<=", ">", ">=", "+", "-", "*", "/", "%"}
)


@dataclass(frozen=True, slots=True)
class Expression:
    """Base of every expression node."""


@dataclass(frozen=True, slots=True)
class Literal(Expression):
    """A constant: string, number, boolean or ``None`` (``null``)."""

    value: str | int | float | bool | None


@dataclass(frozen=True, slots=True)
class Name(Expression):
    """A reference to a data field, possibly a dotted path into a record (``order.total``)."""

    path: tuple[str, ...]

    @property
    def root(self) -> str:
        return self.path[0]


@dataclass(frozen=True, slots=True)
class Unary(Expression):
    op: str
    operand: Expression


@dataclass(frozen=True, slots=True)
class Binary(Expression):
    op: str
    left: Expression
    right: Expression


@dataclass(frozen=True, slots=True)
class Call(Expression):
    """A call of a whitelisted function (``abs``, ``min``, ``max``, ``len``, string helpers).

    The set of callable names is fixed by the evaluator; the parser rejects any other name at
    load time.
    """

    function: str
    args: tuple[Expression, ...]
