"""Text forms of SISARL-XPDL values and the ``opspec:`` extended attributes that state the
model's directives, built-ins, metrics and modes (the inverse of :mod:`opspec.xpdl.sisarl`).

Pure text, no lxml: the writer puts these into the tree. Every text form parses back to the same
value with :mod:`opspec.xpdl.sisarl_values` (the writer tests check it).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from decimal import Decimal
from typing import Any
from xml.sax.saxutils import quoteattr

from opspec.clock import time_of_day
from opspec.model import (
    ActivityDirectives,
    CoordinationBuiltIn,
    CoordinationKind,
    DeclaredDistribution,
    EventSelector,
    Expression,
    ExtendedAttribute,
    Literal,
    MetricDefinition,
    MetricKind,
    Package,
    ProcessDirectives,
    TriggerRef,
    WorkflowMode,
)
from opspec.model.expression_text import to_text

__all__ = [
    "activity_directive_attributes",
    "builtin_attribute",
    "distribution_text",
    "duration_text",
    "expression_text",
    "literal_text",
    "merged_attributes",
    "number_text",
    "package_directive_attributes",
    "process_directive_attributes",
    "trigger_text",
]


def _bool(value: bool) -> str:
    return "true" if value else "false"


# --------------------------------------------------------------------------- text forms


def expression_text(expression: Expression) -> str:
    """JavaScript-style text of an expression tree (``n < 3 && !done``) that the condition
    parser reads back to the same tree (the model's shared printer)."""
    return to_text(expression)


def literal_text(value: str | float | bool | None) -> str:
    return to_text(Literal(value))


def duration_text(seconds: float) -> str:
    """ISO 8601 duration in seconds (``PT0.1S``, ``PT300S``) that parses back to ``seconds``."""
    if math.isinf(seconds) or math.isnan(seconds):
        raise ValueError(f"cannot write a duration of {seconds} seconds")
    if float(seconds).is_integer():
        return f"PT{int(seconds)}S"
    return f"PT{Decimal(repr(float(seconds))):f}S"


def number_text(value: float) -> str:
    if float(value).is_integer() and abs(value) < 2**53:
        return str(int(value))
    return f"{Decimal(repr(float(value))):f}"


def trigger_text(trigger: TriggerRef) -> str:
    """The SISARL trigger syntax of ``trigger`` (``message:trg_1``, ``timer:08:00 every P1D``,
    ``period:PT0.1S offset PT1S``, ``rule:n > 3``)."""
    kind = trigger.kind
    if kind == "none":
        return "none"
    if kind in ("message", "signal"):
        return f"{kind}:{trigger.name or ''}"
    if kind == "rule":
        condition = expression_text(trigger.condition) if trigger.condition else "true"
        return f"rule:{condition}"
    if kind == "period":
        text = f"period:{duration_text(trigger.every or 0.0)}"
        if trigger.offset:
            text += f" offset {duration_text(trigger.offset)}"
        return text
    if kind == "timer":
        if trigger.at:
            text = "timer:" + ",".join(time_of_day(t) for t in trigger.at)
            if trigger.every is not None:
                text += f" every {duration_text(trigger.every)}"
            return text
        return f"timer:after {duration_text(trigger.offset)}"
    return f"{kind}:{trigger.name or ''}"


def distribution_text(distribution: DeclaredDistribution) -> str:
    """``Name(key=value, …)`` (BPSim names where BPSim has them)."""
    parameters = ", ".join(f"{k}={number_text(v)}" for k, v in distribution.parameters)
    return f"{distribution.kind}({parameters})"



def merged_attributes(
    verbatim: tuple[ExtendedAttribute, ...], generated: list[ExtendedAttribute]
) -> list[ExtendedAttribute]:
    present = {attribute.name for attribute in verbatim}
    # A kept alias states the same directive (Rate = 1/Period, Latency = Deadline).
    present |= {_ALIASES[name] for name in present if name in _ALIASES}
    return list(verbatim) + [a for a in generated if a.name not in present]


_ALIASES = {"opspec:Rate": "opspec:Period", "opspec:Latency": "opspec:Deadline"}


def _ea(name: str, value: str | None = None, raw_xml: str | None = None) -> ExtendedAttribute:
    return ExtendedAttribute(name=f"opspec:{name}", value=value, raw_xml=raw_xml)


def _attr_xml(local: str, attributes: dict[str, str | None], children: str = "") -> str:
    """``<opspec:local a="…">children</opspec:local>`` (the prefix is declared by the caller)."""
    attrs = "".join(f" {k}={quoteattr(v)}" for k, v in attributes.items() if v is not None)
    if not children:
        return f"<opspec:{local}{attrs}/>"
    return f"<opspec:{local}{attrs}>{children}</opspec:{local}>"


# What each directive field is written as: (field, opspec: name, its text), in the order the
# writer puts them; a process's and an activity's directives each have some of these fields.
_DIRECTIVES: tuple[tuple[str, str, Callable[[Any], str]], ...] = (
    ("period", "Period", duration_text),
    ("priority", "Priority", str),
    ("deadline", "Deadline", duration_text),
    ("auto_run", "AutoRun", _bool),
    ("priority_increment", "PriorityIncrement", str),
    ("start_trigger", "StartTrigger", trigger_text),
    ("end_trigger", "EndTrigger", trigger_text),
    ("auto_start", "AutoStart", _bool),
    ("lane", "Lane", str),
    ("mode", "Mode", str),
    ("arrival", "Arrival", distribution_text),
    ("arrival_count", "ArrivalCount", str),
    ("raises", "Raises", trigger_text),
    ("cpu_demand", "CpuDemand", duration_text),
    ("cpu_distribution", "CpuDemand", distribution_text),
    ("duration", "Duration", distribution_text),
)


def _stated(directives: ProcessDirectives | ActivityDirectives) -> list[ExtendedAttribute]:
    """The ``opspec:`` extended attributes of the directives that differ from their default."""
    defaults = {f.name: f.default for f in dataclasses.fields(directives)}
    return [_ea(name, text(getattr(directives, field))) for field, name, text in _DIRECTIVES
            if field in defaults and getattr(directives, field) != defaults[field]]


def process_directive_attributes(directives: ProcessDirectives) -> list[ExtendedAttribute]:
    """The ``opspec:`` extended attributes that state ``directives`` (defaults left out)."""
    return _stated(directives)


def activity_directive_attributes(directives: ActivityDirectives) -> list[ExtendedAttribute]:
    """The ``opspec:`` extended attributes that state activity ``directives``."""
    return _stated(directives)


def builtin_attribute(builtin: CoordinationBuiltIn) -> ExtendedAttribute:
    """``opspec:BuiltIn`` with the built-in's element, as ``docs/sisarl-xpdl.md`` writes it."""
    kind = builtin.kind
    if kind is CoordinationKind.PUSH_DATA or kind is CoordinationKind.PULL_DATA:
        local = "PushData" if kind is CoordinationKind.PUSH_DATA else "PullData"
        ref = builtin.inputs[0] if kind is CoordinationKind.PUSH_DATA and builtin.inputs \
            else builtin.output
        return _ea("BuiltIn", raw_xml=_attr_xml(local, {"Channel": builtin.channel, "Ref": ref}))
    if kind is CoordinationKind.MODE_CHANGE:
        return _ea("BuiltIn", raw_xml=_attr_xml("ModeChange", {"To": builtin.target_mode}))
    local = {CoordinationKind.ARBITER: "Arbiter", CoordinationKind.VOTER: "Voter",
             CoordinationKind.SUPERPOSITION: "Superposition"}[kind]
    attributes: dict[str, str | None] = {"Output": builtin.output}
    if builtin.options:
        attributes["Options"] = " ".join(builtin.options)
    inputs = []
    for index, ref in enumerate(builtin.inputs):
        weight = builtin.weights[index] if index < len(builtin.weights) else None
        inputs.append(_attr_xml("Input", {
            "Ref": ref, "Weight": None if weight is None else number_text(weight)}))
    return _ea("BuiltIn", raw_xml=_attr_xml(local, attributes, "".join(inputs)))


def _selector_xml(local: str, selector: EventSelector, name: str | None = None) -> str:
    return _attr_xml(local, {
        "Name": name, "Event": selector.event, "Process": selector.process,
        "Activity": selector.activity,
        "Which": selector.which if selector.which != "first" or local == "From" else None,
    })


def _metric_xml(metric: MetricDefinition) -> str:
    if metric.kind is MetricKind.COUNT and metric.select is not None:
        base = {"Name": metric.name, "Event": metric.select.event,
                "Process": metric.select.process, "Activity": metric.select.activity}
        return _attr_xml("Count", {**base, "Unit": metric.unit,
                                   "Description": metric.description})
    if metric.kind is MetricKind.DURATION:
        children = ""
        if metric.start is not None:
            children += _selector_xml("From", metric.start)
        if metric.end is not None:
            children += _selector_xml("To", metric.end)
        return _attr_xml("Duration", {"Name": metric.name, "Unit": metric.unit,
                                      "Description": metric.description}, children)
    return _attr_xml("Ratio", {"Name": metric.name, "Numerator": metric.numerator,
                               "Denominator": metric.denominator,
                               "Proportion": "true" if metric.proportion else None,
                               "Unit": metric.unit, "Description": metric.description})


def _mode_xml(mode: WorkflowMode) -> str:
    return _attr_xml("Mode", {
        "Id": mode.id, "Initial": "true" if mode.initial else None,
        "Workflows": " ".join(mode.workflows), "Source": mode.source})


def package_directive_attributes(package: Package) -> list[ExtendedAttribute]:
    out: list[ExtendedAttribute] = []
    if package.metrics:
        out.append(_ea("Metrics", raw_xml="".join(_metric_xml(m) for m in package.metrics)))
    if package.modes:
        out.append(_ea("Modes", raw_xml="".join(_mode_xml(m) for m in package.modes)))
    if package.run_length is not None:
        out.append(_ea("RunLength", value=f"PT{package.run_length!r}S"))
    if package.message_ttl is not None:
        out.append(_ea("MessageTTL", value=f"PT{package.message_ttl!r}S"))
    return out
