"""Parsers for the values of SISARL-XPDL directives: triggers, distributions, booleans,
integers, durations and rates (syntax in ``docs/sisarl-xpdl.md``).

Every parser takes the text and its :class:`~opspec.errors.SourceLocation` and either returns
the model value or raises :class:`SisarlValueError` whose message says what is allowed.
"""

from __future__ import annotations

import math
import re
from typing import Final

from opspec.clock import parse_duration, parse_rate, parse_time_of_day
from opspec.errors import SourceLocation, SpecError
from opspec.model.sisarl import DeclaredDistribution, TriggerRef

__all__ = [
    "DISTRIBUTIONS",
    "TRIGGER_KINDS",
    "SisarlValueError",
    "parse_boolean",
    "parse_distribution",
    "parse_integer",
    "parse_period",
    "parse_probability",
    "parse_seconds",
    "parse_trigger",
]


class SisarlValueError(SpecError):
    """A directive's value does not follow its syntax."""


TRIGGER_KINDS: Final = ("none", "message", "signal", "timer", "period", "rule")
_TRIGGER_SYNTAX: Final = (
    "none | message:NAME | signal:NAME | timer:HH:MM[,HH:MM...] [every DURATION] | "
    "timer:after DURATION | period:DURATION [offset DURATION] | rule:CONDITION"
)

# DeclaredDistribution kind -> (positional parameter names, required parameters as alternatives).
DISTRIBUTIONS: Final[dict[str, tuple[tuple[str, ...], tuple[tuple[str, ...], ...]]]] = {
    "ConstantParameter": (("value",), (("value",),)),
    "NormalDistribution": (("mean", "standardDeviation"), (("mean",), ("standardDeviation",))),
    "LogNormalDistribution": (("mean", "standardDeviation"), (("mean",), ("standardDeviation",))),
    "UniformDistribution": (("min", "max"), (("min",), ("max",))),
    "ExponentialDistribution": (("mean",), (("mean",),)),
    "TriangularDistribution": (("min", "mode", "max"), (("min",), ("mode",), ("max",))),
    "GammaDistribution": (("shape", "scale"), (("shape",), ("scale",))),
    "WeibullDistribution": (("shape", "scale"), (("shape",), ("scale",))),
    "TruncatedNormalDistribution": (
        ("mean", "standardDeviation", "min", "max"),
        (("mean",), ("standardDeviation",), ("min",), ("max",)),
    ),
    "constant": (("value",), (("value", "mean"),)),
    "normal": (("mean", "sd"), (("mean",), ("sd", "standardDeviation", "sigma"))),
    "lognormal": (("median", "sigma"), (("median", "mu", "mean"), ("sigma", "sd", "standardDeviation"))),
    "uniform": (("low", "high"), (("low", "min"), ("high", "max"))),
    "exponential": (("mean",), (("mean", "rate"),)),
    "triangular": (("low", "mode", "high"), (("low", "min"), ("mode",), ("high", "max"))),
    "gamma": (("shape", "scale"), (("shape",), ("scale",))),
    "weibull": (("shape", "scale"), (("shape",), ("scale",))),
    "exgauss": (("mu", "sigma", "tau"), (("mu",), ("sigma",), ("tau",))),
}
_POSITIVE: Final = frozenset({"standardDeviation", "sd", "sigma", "shape", "scale", "tau", "rate"})
_CALL = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*$", re.DOTALL)


def _detail(error: Exception) -> str:
    return str(getattr(error, "message", error))


def _fail(message: str, location: SourceLocation | None, hint: str) -> SisarlValueError:
    return SisarlValueError(message, location=location, hint=hint)


def parse_seconds(text: str, location: SourceLocation | None, what: str) -> float:
    """A duration in seconds (``PT0.1S``, ``100ms``, ``0.1``), read by :mod:`opspec.clock`."""
    try:
        return parse_duration(text, location=location, error=SisarlValueError)
    except SisarlValueError as error:
        raise _fail(f"{what}: {error.message}", location, error.hint) from None


def parse_period(text: str, location: SourceLocation | None, *, rate: bool) -> float:
    """The period in seconds of ``opspec:Period`` (a duration) or ``opspec:Rate`` (1/rate)."""
    if not rate:
        seconds = parse_seconds(text, location, "period")
        if seconds <= 0:
            raise _fail(f"period {text!r} must be longer than zero", location, "write e.g. PT0.1S")
        return seconds
    try:
        return 1.0 / parse_rate(text, location=location, error=SisarlValueError)
    except SisarlValueError as error:
        raise _fail(f"rate: {error.message}", location, error.hint) from None


def parse_boolean(text: str, location: SourceLocation | None, what: str) -> bool:
    lowered = text.strip().lower()
    if lowered == "true":
        return True
    if lowered == "false":
        return False
    raise _fail(f"{what} must be true or false, not {text!r}", location, "write true or false")


def parse_integer(text: str, location: SourceLocation | None, what: str) -> int:
    try:
        return int(text.strip())
    except ValueError:
        raise _fail(f"{what} must be an integer, not {text!r}", location, "write e.g. 2") from None


def _name(kind: str, rest: str, location: SourceLocation | None) -> str:
    name = rest.strip()
    if not name:
        raise _fail(f"{kind} trigger needs a name: {kind}:NAME", location, _TRIGGER_SYNTAX)
    return name


def _timer(rest: str, location: SourceLocation | None) -> TriggerRef:
    body = rest.strip()
    if body.startswith("after"):
        delay = parse_seconds(body[len("after"):].strip(), location, "timer delay")
        return TriggerRef(kind="timer", offset=delay, location=location)
    times_text, _, every_text = body.partition(" every ")
    if not times_text.strip():
        raise _fail("timer trigger needs times of day or 'after DURATION'", location, _TRIGGER_SYNTAX)
    times: list[float] = []
    for item in times_text.split(","):
        try:
            times.append(parse_time_of_day(item.strip(), location=location,
                                           error=SisarlValueError))
        except SisarlValueError as error:
            raise _fail(f"timer time: {error.message}", location,
                        "write times as HH:MM, e.g. timer:08:00,20:00") from None
    every = parse_seconds(every_text, location, "timer repetition") if every_text.strip() else 86400.0
    if every <= 0:
        raise _fail("timer repetition must be longer than zero", location, "write e.g. every P1D")
    return TriggerRef(kind="timer", at=tuple(times), every=every, location=location)


def _period(rest: str, location: SourceLocation | None) -> TriggerRef:
    period_text, _, offset_text = rest.strip().partition(" offset ")
    every = parse_seconds(period_text, location, "trigger period")
    if every <= 0:
        raise _fail("trigger period must be longer than zero", location, "write e.g. period:PT1S")
    offset = parse_seconds(offset_text, location, "trigger offset") if offset_text.strip() else 0.0
    return TriggerRef(kind="period", every=every, offset=offset, location=location)


def _rule(rest: str, location: SourceLocation | None) -> TriggerRef:
    from opspec.xpdl.conditions import parse_condition

    if not rest.strip():
        raise _fail("rule trigger needs a condition: rule:CONDITION", location, _TRIGGER_SYNTAX)
    try:
        condition = parse_condition(rest, location=location)
    except (SpecError, ValueError) as error:
        raise _fail(f"rule condition {rest.strip()!r} cannot be understood: {_detail(error)}",
                    location, "write an expression over data fields, e.g. rule:level < 10") from None
    return TriggerRef(kind="rule", condition=condition, location=location)


def parse_trigger(text: str, location: SourceLocation | None = None) -> TriggerRef:
    """A trigger string (split at the first colon only)."""
    stripped = text.strip()
    kind, colon, rest = stripped.partition(":")
    kind = kind.strip().lower()
    if kind == "none" and not rest.strip():
        return TriggerRef(kind="none", location=location)
    if not colon or kind not in TRIGGER_KINDS:
        raise _fail(f"unknown trigger {stripped!r}; allowed kinds: {', '.join(TRIGGER_KINDS)}",
                    location, _TRIGGER_SYNTAX)
    if kind in ("message", "signal"):
        return TriggerRef(kind=kind, name=_name(kind, rest, location), location=location)
    if kind == "timer":
        return _timer(rest, location)
    if kind == "period":
        return _period(rest, location)
    if kind == "rule":
        return _rule(rest, location)
    raise _fail(f"trigger 'none' takes no value, got {stripped!r}", location, _TRIGGER_SYNTAX)


def _number(key: str, text: str, kind: str, location: SourceLocation | None) -> float:
    try:
        value = float(text)
    except ValueError:
        value = parse_seconds(text, location, f"parameter {key} of {kind}")
    if not math.isfinite(value):
        raise _fail(f"parameter {key} of {kind} must be finite, not {text!r}", location,
                    "write a number")
    if key in _POSITIVE and value <= 0:
        raise _fail(f"parameter {key} of {kind} must be greater than zero, not {text!r}",
                    location, "write a positive number")
    return value


def parse_distribution(text: str, location: SourceLocation | None = None) -> DeclaredDistribution:
    """``Name(key=value, …)`` or ``Name(value, …)``; a bare number or duration is a constant."""
    match = _CALL.match(text)
    known = ", ".join(DISTRIBUTIONS)
    if match is None:
        try:
            value = parse_seconds(text, location, "duration")
        except SisarlValueError:
            raise _fail(f"{text.strip()!r} is not a distribution", location,
                        f"write Name(key=value, ...) with Name one of {known}") from None
        return DeclaredDistribution(kind="ConstantParameter", parameters=(("value", value),))
    kind, body = match.group(1), match.group(2)
    spec = DISTRIBUTIONS.get(kind)
    if spec is None:
        raise _fail(f"unknown distribution {kind!r}", location, f"use one of {known}")
    positional, required = spec
    allowed = {name for group in required for name in group} | set(positional)
    parameters: list[tuple[str, float]] = []
    items = [item.strip() for item in body.split(",")] if body.strip() else []
    for index, item in enumerate(items):
        key, equals, value_text = item.partition("=")
        if not equals:
            if index >= len(positional):
                raise _fail(f"{kind} takes at most {len(positional)} values, got {len(items)}",
                            location, f"write {kind}({', '.join(positional)})")
            key, value_text = positional[index], item
        key = key.strip()
        if key not in allowed:
            raise _fail(f"{kind} has no parameter {key!r}", location,
                        f"parameters of {kind}: {', '.join(sorted(allowed))}")
        if any(key == seen for seen, _ in parameters):
            raise _fail(f"parameter {key!r} of {kind} is given twice", location, "give it once")
        parameters.append((key, _number(key, value_text.strip(), kind, location)))
    given = {key for key, _ in parameters}
    for group in required:
        if not given & set(group):
            raise _fail(f"{kind} needs parameter {' or '.join(group)}", location,
                        f"write {kind}({', '.join(f'{p}=…' for p in positional)})")
    return DeclaredDistribution(kind=kind, parameters=tuple(parameters))


def parse_probability(raw: str) -> float | None:
    """``raw`` as a branch probability (``0.25``, ``25%``), or ``None`` when it is none: a
    gateway's branch probabilities (``opspec:Probability``, BPSim, QBP: docs/bpmn.md)."""
    text = raw.strip()
    scale = 1.0
    if text.endswith("%"):
        text, scale = text[:-1].strip(), 0.01
    try:
        value = float(text) * scale
    except ValueError:
        return None
    if not math.isfinite(value) or value < 0.0 or value > 1.0:
        return None
    return value
