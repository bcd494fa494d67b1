"""The fixed whitelist of functions a condition may call, with their arity.

The condition parser (:mod:`opspec.xpdl.conditions`) rejects any other function name at load
time; the evaluator (:mod:`opspec.engine.conditions`) implements exactly these names. The table
lives in the model so both sides import it without the engine importing the XPDL front end.

Java-ish method spellings found in real files are mapped onto these names by the parser:
``x.equals(y)`` becomes ``x == y``, ``x.compareTo(y)`` becomes ``compare(x, y)``,
``x.indexOf(y)`` becomes ``find(x, y)``, ``Math.max(a, b)`` becomes ``max(a, b)`` and so on.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

__all__ = ["FUNCTIONS", "TIME_FUNCTIONS", "FunctionSignature"]


@dataclass(frozen=True, slots=True)
class FunctionSignature:
    """A callable name, how many arguments it takes and what it does.

    ``max_args`` is ``None`` for a variadic function (``min``, ``max``).
    """

    name: str
    min_args: int
    max_args: int | None
    summary: str

    def accepts(self, count: int) -> bool:
        """Whether a call with ``count`` arguments is well-formed."""
        return count >= self.min_args and (self.max_args is None or count <= self.max_args)

    def arity_text(self) -> str:
        """Human wording of the arity: ``1 argument``, ``1 or 2 arguments``, ``2 or more``."""
        lo, hi = self.min_args, self.max_args
        if hi is None:
            return f"{lo} or more arguments"
        if lo == hi:
            return f"{lo} argument" + ("" if lo == 1 else "s")
        if hi == lo + 1:
            return f"{lo} or {hi} arguments"
        return f"{lo} to {hi} arguments"


def _table(*signatures: FunctionSignature) -> Mapping[str, FunctionSignature]:
    return MappingProxyType({s.name: s for s in signatures})


FUNCTIONS: Mapping[str, FunctionSignature] = _table(
    FunctionSignature("abs", 1, 1, "absolute value of a number"),
    FunctionSignature("min", 1, None, "smallest argument (same ordering as <)"),
    FunctionSignature("max", 1, None, "largest argument (same ordering as <)"),
    FunctionSignature("round", 1, 2, "round half away from zero; round(x, n) keeps n decimals"),
    FunctionSignature("floor", 1, 1, "largest integer <= x"),
    FunctionSignature("ceil", 1, 1, "smallest integer >= x"),
    FunctionSignature("len", 1, 1, "length of a text, list or record"),
    FunctionSignature("lower", 1, 1, "text in lower case"),
    FunctionSignature("upper", 1, 1, "text in upper case"),
    FunctionSignature("strip", 1, 1, "text without leading and trailing white space"),
    FunctionSignature("contains", 2, 2, "whether text/list/record a contains b"),
    FunctionSignature("startswith", 2, 2, "whether text a starts with text b"),
    FunctionSignature("endswith", 2, 2, "whether text a ends with text b"),
    FunctionSignature("find", 2, 2, "index of text b in text a, -1 when absent (Java indexOf)"),
    FunctionSignature("compare", 2, 2, "-1, 0 or 1 as a < b, a == b, a > b (Java compareTo)"),
    FunctionSignature("str", 1, 1, "value as text (true, false, null, 3, 2.5)"),
    FunctionSignature("int", 1, 1, "value as an integer (truncates toward zero)"),
    FunctionSignature("float", 1, 1, "value as a number"),
    FunctionSignature("bool", 1, 1, "value as a boolean (the truthiness rules)"),
    FunctionSignature("now", 0, 0, "simulated time in seconds"),
    FunctionSignature("time_of_day", 0, 0, "simulated seconds since midnight of the day"),
    FunctionSignature("hour", 0, 0, "hour of the simulated day, 0-23"),
    FunctionSignature("day", 0, 0, "index of the simulated day, starting at 0"),
)
"""Every function a condition may call, by name."""

TIME_FUNCTIONS = frozenset({"now", "time_of_day", "hour", "day"})
"""The functions that read the simulation clock (never the wall clock)."""
