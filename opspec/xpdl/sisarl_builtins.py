"""The structured SISARL-XPDL directives: ``opspec:BuiltIn`` (coordination built-ins),
``opspec:Metrics`` and ``opspec:Modes``. Their content is child elements in the
``urn:opspec:sisarl:1`` namespace inside the ``ExtendedAttribute``."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, TypeVar

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model.sisarl import (
    CoordinationBuiltIn,
    CoordinationKind,
    EventSelector,
    MetricDefinition,
    MetricKind,
    WorkflowMode,
)
from opspec.xpdl.handlers.common import BuildContext
from opspec.xpdl.namespaces import OPSPEC

if TYPE_CHECKING:
    from opspec.xpdl.sisarl import Directive

__all__ = ["BUILT_INS", "build_builtin", "build_metrics", "build_modes"]

_T = TypeVar("_T")

BUILT_INS = ("Arbiter", "Voter", "Superposition", "PushData", "PullData", "ModeChange")
_METRICS = ("Count", "Duration", "Ratio")
_WHICH = ("first", "last")


class _Bad(Exception):
    """Internal: a structured directive is malformed at ``element``."""

    def __init__(self, element: etree._Element, message: str, hint: str) -> None:
        super().__init__(message)
        self.element = element
        self.message = message
        self.hint = hint


def _ours(element: etree._Element) -> list[etree._Element]:
    return [sub for sub in element if isinstance(sub.tag, str) and sub.tag.startswith(f"{{{OPSPEC}}}")]


def _local(element: etree._Element) -> str:
    return str(element.tag).split("}", 1)[-1]


def _need(element: etree._Element, name: str) -> str:
    value = (element.get(name) or "").strip()
    if not value:
        raise _Bad(element, f"opspec:{_local(element)} needs attribute {name}",
                   f"add {name}=\"...\" to <opspec:{_local(element)}>")
    return value


def _report(ctx: BuildContext, error: _Bad, code: str) -> None:
    ctx.diagnostics.append(Diagnostic(ctx.loc(error.element), Severity.ERROR, code, error.message,
                                      error.hint))


def _container(directive: Directive, ctx: BuildContext) -> etree._Element | None:
    if directive.element is None:
        ctx.diagnostics.append(Diagnostic(
            directive.location, Severity.ERROR, "bad-directive",
            f"opspec:{directive.name} cannot be written as an attribute",
            f"write <ExtendedAttribute Name=\"opspec:{directive.name}\"> with child elements"))
        return None
    return directive.element


def _inputs(element: etree._Element) -> list[etree._Element]:
    return [sub for sub in _ours(element) if _local(sub) == "Input"]


def _builtin(element: etree._Element) -> CoordinationBuiltIn:
    kind = _local(element)
    if kind in ("Arbiter", "Voter", "Superposition"):
        output = _need(element, "Output")
        inputs = _inputs(element)
        if not inputs:
            raise _Bad(element, f"opspec:{kind} has no inputs",
                       f"add <opspec:Input Ref=\"data_field\"/> children to <opspec:{kind}>")
        refs = tuple(_need(sub, "Ref") for sub in inputs)
        if kind == "Arbiter":
            return CoordinationBuiltIn(kind=CoordinationKind.ARBITER, inputs=refs, output=output)
        if kind == "Voter":
            options = tuple(_need(element, "Options").split())
            return CoordinationBuiltIn(kind=CoordinationKind.VOTER, inputs=refs, output=output,
                                       options=options)
        weights: list[float] = []
        for sub in inputs:
            text = (sub.get("Weight") or "1").strip()
            try:
                weights.append(float(text))
            except ValueError:
                raise _Bad(sub, f"Weight {text!r} of opspec:Input is not a number",
                           "write a number, e.g. Weight=\"0.7\"") from None
        return CoordinationBuiltIn(kind=CoordinationKind.SUPERPOSITION, inputs=refs,
                                   output=output, weights=tuple(weights))
    if kind == "PushData":
        return CoordinationBuiltIn(kind=CoordinationKind.PUSH_DATA, channel=_need(element, "Channel"),
                                   inputs=(_need(element, "Ref"),))
    if kind == "PullData":
        return CoordinationBuiltIn(kind=CoordinationKind.PULL_DATA, channel=_need(element, "Channel"),
                                   output=_need(element, "Ref"))
    if kind == "ModeChange":
        return CoordinationBuiltIn(kind=CoordinationKind.MODE_CHANGE,
                                   target_mode=_need(element, "To"))
    raise _Bad(element, f"unknown built-in opspec:{kind}",
               f"use one of {', '.join('opspec:' + b for b in BUILT_INS)}")


def build_builtin(directive: Directive, ctx: BuildContext) -> CoordinationBuiltIn | None:
    container = _container(directive, ctx)
    if container is None:
        return None
    elements = _ours(container)
    if len(elements) != 1:
        ctx.diagnostics.append(Diagnostic(
            directive.location, Severity.ERROR, "bad-built-in",
            f"opspec:BuiltIn must hold exactly one built-in element, found {len(elements)}",
            f"put one of {', '.join('opspec:' + b for b in BUILT_INS)} inside it"))
        return None
    try:
        return _builtin(elements[0])
    except _Bad as error:
        _report(ctx, error, "bad-built-in")
        return None


def _selector(element: etree._Element) -> EventSelector:
    which = (element.get("Which") or "first").strip()
    if which not in _WHICH:
        raise _Bad(element, f"Which must be first or last, not {which!r}", "write Which=\"first\"")
    return EventSelector(event=_need(element, "Event"), process=element.get("Process"),
                         activity=element.get("Activity"), which=which)


def _flag(element: etree._Element, name: str) -> bool:
    """A ``true``/``false`` attribute (absent: false)."""
    value = (element.get(name) or "false").strip().lower()
    if value not in ("true", "false"):
        raise _Bad(element, f"{name} must be true or false, not {value!r}",
                   f"write {name}=\"true\"")
    return value == "true"


def _metric(element: etree._Element, location: SourceLocation) -> MetricDefinition:
    kind = _local(element)
    name = _need(element, "Name")
    common = {"name": name, "description": element.get("Description"),
              "unit": element.get("Unit"), "location": location}
    if kind != "Ratio" and element.get("Proportion") is not None:
        # a declaration the summaries would not read is one the author believes in vain
        raise _Bad(element, f"Proportion is declared of a ratio, not of opspec:{kind} {name!r}",
                   "put Proportion=\"true\" on the opspec:Ratio that divides this metric")
    if kind == "Count":
        return MetricDefinition(kind=MetricKind.COUNT, select=_selector(element), **common)
    if kind == "Duration":
        ends = {_local(sub): sub for sub in _ours(element)}
        if "From" not in ends or "To" not in ends:
            raise _Bad(element, f"opspec:Duration {name!r} needs opspec:From and opspec:To",
                       "add <opspec:From Event=.../> and <opspec:To Event=.../>")
        return MetricDefinition(kind=MetricKind.DURATION, start=_selector(ends["From"]),
                                end=_selector(ends["To"]), **common)
    if kind == "Ratio":
        return MetricDefinition(kind=MetricKind.RATIO, numerator=_need(element, "Numerator"),
                                denominator=_need(element, "Denominator"),
                                proportion=_flag(element, "Proportion"), **common)
    raise _Bad(element, f"unknown metric opspec:{kind}",
               f"use one of {', '.join('opspec:' + m for m in _METRICS)}")


def _declarations(directive: Directive, ctx: BuildContext, build: Callable[[etree._Element], _T],
                  key: Callable[[_T], str], code: str, noun: str, hint: str) -> tuple[_T, ...]:
    """Each element the directive's container holds, built by ``build``; one that is bad, or
    whose ``key`` an earlier one has already, is reported as ``code`` and left out."""
    container = _container(directive, ctx)
    if container is None:
        return ()
    built: list[_T] = []
    for element in _ours(container):
        try:
            item = build(element)
        except _Bad as error:
            _report(ctx, error, code)
            continue
        if any(key(b) == key(item) for b in built):
            _report(ctx, _Bad(element, f"{noun} {key(item)!r} is declared twice", hint), code)
            continue
        built.append(item)
    return tuple(built)


def build_metrics(directive: Directive, ctx: BuildContext) -> tuple[MetricDefinition, ...]:
    metrics = _declarations(directive, ctx, lambda element: _metric(element, ctx.loc(element)),
                            lambda metric: metric.name, "bad-metric", "metric",
                            "give every metric its own Name")
    counts = {m.name for m in metrics if m.kind is MetricKind.COUNT}
    declared = {m.name for m in metrics}
    for metric in metrics:
        # whole events of whole trials or Wilson's interval means nothing; a name that is no
        # metric at all is checks_refs' to report
        wrong = [ref for ref in (metric.numerator, metric.denominator)
                 if metric.proportion and ref in declared and ref not in counts]
        if wrong:
            ctx.diagnostics.append(Diagnostic(
                metric.location, Severity.ERROR, "bad-metric",
                f"opspec:Ratio {metric.name!r} is declared a proportion, but {wrong[0]!r} is "
                "not an opspec:Count: a proportion counts events out of counted trials",
                "leave Proportion out (the ratio's own interval is used), or divide two "
                "opspec:Count metrics"))
    return metrics


def _mode(element: etree._Element, ctx: BuildContext) -> WorkflowMode:
    if _local(element) != "Mode":
        raise _Bad(element, f"opspec:Modes may only hold opspec:Mode, not opspec:{_local(element)}",
                   "write <opspec:Mode Id=... Workflows=.../>")
    initial = _flag(element, "Initial")
    return WorkflowMode(id=_need(element, "Id"),
                        workflows=tuple((element.get("Workflows") or "").split()),
                        initial=initial, source=element.get("Source"),
                        location=ctx.loc(element))


def build_modes(directive: Directive, ctx: BuildContext) -> tuple[WorkflowMode, ...]:
    modes = _declarations(directive, ctx, lambda element: _mode(element, ctx),
                          lambda mode: mode.id, "bad-mode", "mode", "give every mode its own Id")
    if modes and sum(m.initial for m in modes) > 1:
        ctx.diagnostics.append(Diagnostic(directive.location, Severity.ERROR, "bad-mode",
                                          "more than one mode is Initial=\"true\"",
                                          "mark exactly one mode as initial"))
    return modes
