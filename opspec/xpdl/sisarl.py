"""SISARL-XPDL extensions: engine directives, coordination built-ins, metrics and modes.

Directives are ``ExtendedAttribute``s named ``opspec:NAME`` (value in ``Value`` or the text),
or, as a shorthand, attributes ``opspec:NAME`` in the ``urn:opspec:sisarl:1`` namespace on the
element; both give the same model. Unknown ``opspec:`` names are ``unknown-directive``
warnings; bad values are ``bad-directive`` errors naming file:line and what is allowed.
The syntax is documented in ``docs/sisarl-xpdl.md``.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model.sisarl import (
    ActivityDirectives,
    CoordinationBuiltIn,
    DeclaredDistribution,
    ProcessDirectives,
    WorkflowMode,
)
from opspec.xpdl.handlers.common import BuildContext, grandchildren
from opspec.xpdl.namespaces import OPSPEC, OPSPEC_PREFIX
from opspec.xpdl.sisarl_values import (
    SisarlValueError,
    parse_boolean,
    parse_distribution,
    parse_integer,
    parse_period,
    parse_seconds,
    parse_trigger,
)

__all__ = [
    "ACTIVITY_DIRECTIVES",
    "MAX_ATTRIBUTES",
    "PACKAGE_DIRECTIVES",
    "PROCESS_DIRECTIVES",
    "Directive",
    "activity_directives",
    "package_extensions",
    "process_directives",
]


@dataclass(frozen=True, slots=True)
class Directive:
    """One ``opspec:`` directive as written: its name (without prefix), its value text, the
    ``ExtendedAttribute`` element when written in that form, and where it is."""

    name: str
    value: str
    element: etree._Element | None
    location: SourceLocation


PROCESS_DIRECTIVES = ("Period", "Rate", "Priority", "Deadline", "Latency", "StartTrigger",
                      "EndTrigger", "AutoStart", "Lane", "Mode", "Arrival", "ArrivalCount")
ACTIVITY_DIRECTIVES = ("AutoRun", "PriorityIncrement", "StartTrigger", "EndTrigger", "Raises",
                       "CpuDemand", "Duration", "BuiltIn")
PACKAGE_DIRECTIVES = ("Metrics", "Modes", "Monitor", "World", "WorldFile", "RunLength",
                      "MessageTTL")
#: directives that may be given more than once, every one counting (one monitor per attribute)
REPEATABLE = frozenset({"Monitor"})

#: Most attributes one Package, WorkflowProcess or Activity element may carry (XPDL defines
#: fewer than twenty); more is a damaged or hostile file, reported as ``too-many-attributes``.
MAX_ATTRIBUTES = 1024


def collect(element: etree._Element, ctx: BuildContext, known: tuple[str, ...],
            what: str) -> dict[str, Directive]:
    """Every ``opspec:`` directive on ``element`` (both forms), warning about unknown names."""
    found: dict[str, Directive] = {}

    def add(directive: Directive) -> None:
        if directive.name not in known:
            ctx.diagnostics.append(_diag(directive.location, "warning", "unknown-directive",
                                   f"unknown directive opspec:{directive.name} on {what}",
                                   _unknown_hint(directive.name, known, what)))
            return
        if directive.name in found and directive.name not in REPEATABLE:
            ctx.diagnostics.append(_diag(directive.location, "warning", "duplicate-directive",
                                   f"opspec:{directive.name} is given twice on {what}; the "
                                   "last one counts", "remove one of them"))
        found[directive.name] = directive

    # ``attrib.items()`` is quadratic in lxml (each item is looked up from the start of the
    # element's attribute list): a hostile element with 200,000 attributes took minutes.
    # ``keys()`` is linear, and only the few opspec-namespaced names are then looked up.
    count = len(element.attrib)
    if count > MAX_ATTRIBUTES:
        ctx.diagnostics.append(_diag(
            ctx.loc(element), "error", "too-many-attributes",
            f"{what} has {count:,} attributes, more than the limit of {MAX_ATTRIBUTES}; "
            "its opspec: attributes were not read",
            "XPDL elements need a handful of attributes; remove the extra ones (was the "
            "file generated or damaged?)"))
    else:
        prefix = f"{{{OPSPEC}}}"
        for name in element.keys():  # noqa: SIM118 - iterating an element gives children
            if name.startswith(prefix):
                add(Directive(name[len(prefix):], element.get(name) or "", None,
                              ctx.loc(element)))
    for ext in grandchildren(element, "ExtendedAttributes", "ExtendedAttribute"):
        name = ext.get("Name") or ""
        if name.startswith(OPSPEC_PREFIX):
            value = ext.get("Value")
            if value is None:
                value = (ext.text or "").strip()
            add(Directive(name[len(OPSPEC_PREFIX):], value, ext, ctx.loc(ext)))
        else:
            meant = _misspelt_prefix(name, known)
            if meant is not None:
                # ``opspc:StartTrigger`` or ``StartTrigger``: read by nobody, so the spec
                # would silently run without it
                ctx.diagnostics.append(_diag(
                    ctx.loc(ext), "warning", "unknown-directive",
                    f"ExtendedAttribute {name!r} on {what} is not an opspec directive and is "
                    "ignored", f"did you mean opspec:{meant}? (directives are named "
                    "opspec:NAME)"))
    return found


_SCOPES = {"a Package": PACKAGE_DIRECTIVES, "a WorkflowProcess": PROCESS_DIRECTIVES,
           "an Activity": ACTIVITY_DIRECTIVES}


def _closest(name: str, known: tuple[str, ...]) -> str | None:
    """The known directive ``name`` is most likely a misspelling of (case-insensitive)."""
    lowered = {k.lower(): k for k in known}
    close = difflib.get_close_matches(name.lower(), list(lowered), n=1, cutoff=0.75)
    return lowered[close[0]] if close else None


def _unknown_hint(name: str, known: tuple[str, ...], what: str) -> str:
    """Did you mean the closest known directive, or is it one of another element?"""
    listing = f"known on {what}: {', '.join('opspec:' + k for k in known)}"
    close = _closest(name, known)
    if close is not None:
        return f"did you mean opspec:{close}? {listing}"
    elsewhere = [scope for scope, names in _SCOPES.items() if name in names and scope != what]
    if elsewhere:
        return (f"opspec:{name} is a directive of {' or '.join(elsewhere)}, not of {what}; "
                f"{listing}")
    return listing


def _misspelt_prefix(name: str, known: tuple[str, ...]) -> str | None:
    """The directive an ExtendedAttribute without the ``opspec:`` prefix was meant to be:
    its last part names a known directive exactly (any case) and its prefix, if any, is close
    to ``opspec`` (``opspc:Lane``, ``OpSpec.Lane``, ``Lane``). Other tools' names (JaWE's
    ``JaWE_GRAPH_…``) are left alone."""
    head, _, tail = name.replace(".", ":").rpartition(":")
    match = {k.lower(): k for k in known}.get(tail.strip().lower())
    if match is None:
        return None
    prefix = OPSPEC_PREFIX.rstrip(":")
    if head and not difflib.get_close_matches(head.lower(), [prefix], n=1, cutoff=0.6):
        return None
    return match


def _diag(location: SourceLocation, severity: str, code: str, message: str, hint: str) -> Diagnostic:
    return Diagnostic(location, Severity(severity), code, message, hint)


def _apply(directives: dict[str, Directive], ctx: BuildContext,
           parsers: dict[str, tuple[str, Callable[[Directive], Any]]]) -> dict[str, Any]:
    """Parse each directive with its parser into a model field; bad values are errors."""
    values: dict[str, Any] = {}
    for name, directive in directives.items():
        if name not in parsers:
            continue
        field_name, parse = parsers[name]
        try:
            values[field_name] = parse(directive)
        except SisarlValueError as error:
            ctx.diagnostics.append(_diag(directive.location, "error", "bad-directive",
                                         f"opspec:{name}: {error.message}", error.hint))
    return values


def _lane(directive: Directive) -> str:
    value = directive.value.strip()
    if value not in ("user", "device"):
        raise SisarlValueError(f"lane must be 'user' or 'device', not {value!r}",
                               location=directive.location, hint="write user or device")
    return value


def _positive_seconds(directive: Directive, what: str, hint: str) -> float:
    """The duration ``directive`` states, in seconds; zero or less is an error naming ``what``."""
    seconds = parse_seconds(directive.value, directive.location, what)
    if seconds <= 0:
        raise SisarlValueError(f"{what} {directive.value!r} must be longer than zero",
                               location=directive.location, hint=hint)
    return seconds


def _run_length(directive: Directive) -> float:
    return _positive_seconds(directive, "run length", "write e.g. PT1H")


def _message_ttl(directive: Directive) -> float:
    return _positive_seconds(directive, "message time to live",
                             "write e.g. PT60S (leave it out to keep messages until caught)")


def _mode_id(directive: Directive) -> str:
    value = directive.value.strip()
    if not value:
        raise SisarlValueError("mode id is empty", location=directive.location,
                               hint="name a mode declared in opspec:Modes")
    return value


def process_directives(element: etree._Element, ctx: BuildContext,
                       found: dict[str, Directive] | None = None) -> ProcessDirectives:
    """The :class:`ProcessDirectives` of a ``WorkflowProcess`` element (``found``: the
    directives already collected, as the BPMN reader collects them from extensionElements)."""
    if found is None:
        found = collect(element, ctx, PROCESS_DIRECTIVES, "a WorkflowProcess")
    if "Deadline" in found and "Latency" in found:
        ctx.diagnostics.append(_diag(found["Latency"].location, "warning", "duplicate-directive",
                               "opspec:Latency is an alias of opspec:Deadline; Deadline counts",
                               "keep one of them"))
        del found["Latency"]
    if "Period" in found and "Rate" in found:
        ctx.diagnostics.append(_diag(found["Rate"].location, "warning", "duplicate-directive",
                               "opspec:Rate and opspec:Period both given; Period counts",
                               "keep one of them"))
        del found["Rate"]
    values = _apply(found, ctx, {
        "Period": ("period", lambda d: parse_period(d.value, d.location, rate=False)),
        "Rate": ("period", lambda d: parse_period(d.value, d.location, rate=True)),
        "Priority": ("priority", lambda d: parse_integer(d.value, d.location, "priority")),
        "Deadline": ("deadline", lambda d: parse_seconds(d.value, d.location, "deadline")),
        "Latency": ("deadline", lambda d: parse_seconds(d.value, d.location, "latency")),
        "StartTrigger": ("start_trigger", lambda d: parse_trigger(d.value, d.location)),
        "EndTrigger": ("end_trigger", lambda d: parse_trigger(d.value, d.location)),
        "AutoStart": ("auto_start", lambda d: parse_boolean(d.value, d.location, "AutoStart")),
        "Lane": ("lane", _lane),
        "Mode": ("mode", _mode_id),
        "Arrival": ("arrival", lambda d: parse_distribution(d.value, d.location)),
        "ArrivalCount": ("arrival_count", _arrival_count),
    })
    return ProcessDirectives(**values)


def _arrival_count(directive: Directive) -> int:
    count = parse_integer(directive.value, directive.location, "ArrivalCount")
    if count < 0:
        raise SisarlValueError(f"ArrivalCount {directive.value.strip()!r} is negative",
                               location=directive.location,
                               hint="write how many instances arrive in all, e.g. 100")
    return count


def activity_directives(
    element: etree._Element, ctx: BuildContext, found: dict[str, Directive] | None = None
) -> tuple[ActivityDirectives, CoordinationBuiltIn | None]:
    """The :class:`ActivityDirectives` and coordination built-in of an ``Activity`` element
    (``found``: the directives already collected, see :func:`process_directives`)."""
    if found is None:
        found = collect(element, ctx, ACTIVITY_DIRECTIVES, "an Activity")
    if not found:
        return _NO_ACTIVITY_DIRECTIVES, None
    values = _apply(found, ctx, _ACTIVITY_PARSERS)
    if isinstance(values.get("cpu_demand"), DeclaredDistribution):
        values["cpu_distribution"] = values.pop("cpu_demand")
    builtin = None
    if "BuiltIn" in found:
        from opspec.xpdl.sisarl_builtins import build_builtin

        builtin = build_builtin(found["BuiltIn"], ctx)
    return ActivityDirectives(**values), builtin


def _cpu_demand(directive: Directive) -> float | DeclaredDistribution:
    """Processor time: a duration, or a distribution drawn at every execution."""
    dist = parse_distribution(directive.value, directive.location)
    if dist.kind == "ConstantParameter" and len(dist.parameters) == 1:
        return float(dist.parameters[0][1])
    return dist


def _raises(directive: Directive) -> Any:
    trigger = parse_trigger(directive.value, directive.location)
    if trigger.kind not in ("message", "signal"):
        raise SisarlValueError(f"an activity can only raise a message or a signal, not "
                               f"{trigger.kind!r}", location=directive.location,
                               hint="write message:NAME or signal:NAME")
    return trigger


_ACTIVITY_PARSERS: dict[str, tuple[str, Callable[[Directive], Any]]] = {
    "AutoRun": ("auto_run", lambda d: parse_boolean(d.value, d.location, "AutoRun")),
    "PriorityIncrement": ("priority_increment",
                          lambda d: parse_integer(d.value, d.location, "PriorityIncrement")),
    "StartTrigger": ("start_trigger", lambda d: parse_trigger(d.value, d.location)),
    "EndTrigger": ("end_trigger", lambda d: parse_trigger(d.value, d.location)),
    "Raises": ("raises", _raises),
    "CpuDemand": ("cpu_demand", lambda d: _cpu_demand(d)),
    "Duration": ("duration", lambda d: parse_distribution(d.value, d.location)),
}
# An activity without directives (shared: the model is immutable).
_NO_ACTIVITY_DIRECTIVES = ActivityDirectives()


def package_extensions(element: etree._Element, ctx: BuildContext,
                       found: dict[str, Directive] | None = None) -> dict[str, Any]:
    """``metrics``, ``modes``, ``run_length`` and ``message_ttl`` of a ``Package`` element, as Package
    keyword arguments (``found``: the directives already collected, see
    :func:`process_directives`)."""
    from opspec.xpdl.sisarl_builtins import build_metrics, build_modes

    if found is None:
        found = collect(element, ctx, PACKAGE_DIRECTIVES, "a Package")
    out: dict[str, Any] = _apply(found, ctx, {"RunLength": ("run_length", _run_length),
                                              "MessageTTL": ("message_ttl", _message_ttl)})
    if "Metrics" in found:
        out["metrics"] = build_metrics(found["Metrics"], ctx)
    if "Modes" in found:
        modes: tuple[WorkflowMode, ...] = build_modes(found["Modes"], ctx)
        out["modes"] = modes
    return out
