"""SISARL-XPDL extensions as written in a file (docs/sisarl-xpdl.md): directives in both forms,
triggers, distributions, coordination built-ins, metrics and modes, and their diagnostics."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import Severity
from opspec.model import (
    Activity,
    CoordinationKind,
    DeclaredDistribution,
    MetricKind,
    WorkflowProcess,
)
from opspec.xpdl import LoadResult, load_package, parse_bytes

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
HEAD = ('<?xml version="1.0"?>\n<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" '
        'xmlns:opspec="urn:opspec:sisarl:1" Id="pkg">')


def ea(name: str, value: str) -> str:
    return f'<ExtendedAttribute Name="opspec:{name}" Value="{value}"/>'


def load_process(process_eas: str = "", activity_eas: str = "", attrs: str = "",
                 activity_attrs: str = "") -> LoadResult:
    text = (f'{HEAD}<WorkflowProcesses><WorkflowProcess Id="p"{attrs}>'
            f'<Activities><Activity Id="a"{activity_attrs}>'
            f"<ExtendedAttributes>{activity_eas}</ExtendedAttributes></Activity></Activities>"
            f"<ExtendedAttributes>{process_eas}</ExtendedAttributes>"
            "</WorkflowProcess></WorkflowProcesses></Package>")
    return parse_bytes(text.encode(), path="s.xpdl")


def process(result: LoadResult) -> WorkflowProcess:
    assert result.package is not None
    return result.package.processes[0]


def activity(result: LoadResult) -> Activity:
    return process(result).activities[0]


def test_reference_dispenser_spec_loads_with_its_directives() -> None:
    result = load_package(SPEC)
    assert result.ok, [str(d) for d in result.diagnostics]
    assert result.package is not None
    timer = result.package.process("timer_workflow")
    assert timer is not None and timer.directives.start_trigger is not None
    trigger = timer.directives.start_trigger
    assert trigger.kind == "timer" and trigger.at == (8 * 3600, 12 * 3600, 18 * 3600, 22 * 3600)
    assert trigger.every == 86400
    assert {m.name for m in result.package.metrics} >= {"doses_due", "report_latency_s", "alarms_per_dose"}


@pytest.mark.parametrize(
    ("name", "value", "field", "expected"),
    [
        ("Period", "PT0.1S", "period", 0.1),
        ("Period", "100ms", "period", 0.1),
        ("Period", "0.1", "period", 0.1),
        ("Rate", "10Hz", "period", 0.1),
        ("Rate", "10/s", "period", 0.1),
        ("Rate", "10", "period", 0.1),
        ("Priority", "3", "priority", 3),
        ("Deadline", "PT2S", "deadline", 2.0),
        ("Latency", "PT2S", "deadline", 2.0),
        ("AutoStart", "true", "auto_start", True),
        ("Lane", "user", "lane", "user"),
        ("Mode", "search", "mode", "search"),
    ],
    ids=lambda v: str(v),
)
def test_process_directive_in_both_forms(name: str, value: str, field: str, expected: object) -> None:
    by_extended = process(load_process(process_eas=ea(name, value))).directives
    by_attribute = process(load_process(attrs=f' opspec:{name}="{value}"')).directives
    assert getattr(by_extended, field) == pytest.approx(expected)
    assert by_extended == by_attribute


@pytest.mark.parametrize(
    ("text", "kind", "check"),
    [
        ("none", "none", {}),
        ("message:trg_2", "message", {"name": "trg_2"}),
        ("signal:bump", "signal", {"name": "bump"}),
        ("timer:08:00,20:30", "timer", {"at": (28800.0, 73800.0), "every": 86400.0}),
        ("timer:08:00 every PT12H", "timer", {"at": (28800.0,), "every": 43200.0}),
        ("timer:after PT30S", "timer", {"offset": 30.0, "at": ()}),
        ("period:PT1S offset PT0.5S", "period", {"every": 1.0, "offset": 0.5}),
        ("rule:level < 10", "rule", {}),
    ],
    ids=lambda v: str(v) if isinstance(v, str) else "",
)
def test_trigger_syntax(text: str, kind: str, check: dict[str, object]) -> None:
    trigger = process(load_process(process_eas=ea("StartTrigger", text.replace("<", "&lt;")))).directives.start_trigger
    assert trigger is not None and trigger.kind == kind
    for key, value in check.items():
        assert getattr(trigger, key) == value
    if kind == "rule":
        assert trigger.condition is not None
    assert trigger.location is not None and trigger.location.line == 2


def test_activity_directives_in_both_forms() -> None:
    eas = (ea("AutoRun", "false") + ea("PriorityIncrement", "2") + ea("StartTrigger", "message:go")
           + ea("EndTrigger", "signal:stop") + ea("Raises", "message:done") + ea("CpuDemand", "5ms")
           + ea("Duration", "LogNormalDistribution(mean=2, standardDeviation=0.5)"))
    attrs = (' opspec:AutoRun="false" opspec:PriorityIncrement="2" opspec:StartTrigger="message:go"'
             ' opspec:EndTrigger="signal:stop" opspec:Raises="message:done" opspec:CpuDemand="5ms"'
             ' opspec:Duration="LogNormalDistribution(mean=2, standardDeviation=0.5)"')
    one = activity(load_process(activity_eas=eas))
    two = activity(load_process(activity_attrs=attrs))
    assert one.directives.auto_run is False and one.is_manual
    assert one.directives.priority_increment == 2
    assert one.directives.cpu_demand == pytest.approx(0.005)
    assert one.directives.raises is not None and one.directives.raises.name == "done"
    assert one.directives.duration == DeclaredDistribution(
        kind="LogNormalDistribution", parameters=(("mean", 2.0), ("standardDeviation", 0.5)))
    assert _no_locations(one.directives) == _no_locations(two.directives)


def _no_locations(directives: object) -> object:
    import dataclasses

    changes = {}
    for field in dataclasses.fields(directives):  # type: ignore[arg-type]
        value = getattr(directives, field.name)
        if dataclasses.is_dataclass(value) and hasattr(value, "location"):
            value = dataclasses.replace(value, location=None)
        changes[field.name] = value
    return dataclasses.replace(directives, **changes)  # type: ignore[type-var]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("ConstantParameter(3)", ("ConstantParameter", (("value", 3.0),))),
        ("NormalDistribution(10, 2)", ("NormalDistribution", (("mean", 10.0), ("standardDeviation", 2.0)))),
        ("UniformDistribution(min=1, max=4)", ("UniformDistribution", (("min", 1.0), ("max", 4.0)))),
        ("ExponentialDistribution(mean=5)", ("ExponentialDistribution", (("mean", 5.0),))),
        ("TriangularDistribution(1, 2, 5)", ("TriangularDistribution", (("min", 1.0), ("mode", 2.0), ("max", 5.0)))),
        ("GammaDistribution(shape=2, scale=3)", ("GammaDistribution", (("shape", 2.0), ("scale", 3.0)))),
        ("WeibullDistribution(1.5, 2)", ("WeibullDistribution", (("shape", 1.5), ("scale", 2.0)))),
        ("TruncatedNormalDistribution(5, 1, 0, 10)", ("TruncatedNormalDistribution",
         (("mean", 5.0), ("standardDeviation", 1.0), ("min", 0.0), ("max", 10.0)))),
        ("lognormal(median=60, sigma=0.6)", ("lognormal", (("median", 60.0), ("sigma", 0.6)))),
        ("exgauss(mu=1, sigma=0.2, tau=0.5)", ("exgauss", (("mu", 1.0), ("sigma", 0.2), ("tau", 0.5)))),
        ("constant(2)", ("constant", (("value", 2.0),))),
        ("PT2S", ("ConstantParameter", (("value", 2.0),))),
    ],
    ids=lambda v: v if isinstance(v, str) else "",
)
def test_distribution_syntax(text: str, expected: tuple[str, tuple[tuple[str, float], ...]]) -> None:
    duration = activity(load_process(activity_eas=ea("Duration", text))).directives.duration
    assert duration == DeclaredDistribution(kind=expected[0], parameters=expected[1])


@pytest.mark.parametrize(
    ("name", "value", "allowed"),
    [
        ("Period", "soon", "ISO 8601"),
        ("Rate", "fast", "10Hz"),
        ("Priority", "high", "integer"),
        ("AutoStart", "yes please", "true or false"),
        ("Lane", "robot", "user or device"),
        ("StartTrigger", "telepathy:now", "message:NAME"),
        ("StartTrigger", "message:", "message:NAME"),
        ("StartTrigger", "timer:25h", "HH:MM"),
        ("StartTrigger", "rule:a ==", "expression"),
    ],
    ids=lambda v: str(v),
)
def test_bad_process_directive_is_an_error_naming_line_and_what_is_allowed(
    name: str, value: str, allowed: str
) -> None:
    result = load_process(process_eas=ea(name, value))
    [error] = result.errors
    assert error.code == "bad-directive" and error.location.line == 2
    assert f"opspec:{name}" in error.message
    assert allowed in f"{error.message} {error.hint}"


@pytest.mark.parametrize(
    ("text", "allowed"),
    [
        ("Banana(1)", "NormalDistribution"),
        ("NormalDistribution(mean=1)", "standardDeviation"),
        ("NormalDistribution(mean=x, standardDeviation=1)", "duration"),
        ("UniformDistribution(1, 2, 3)", "at most 2"),
        ("GammaDistribution(shape=-1, scale=1)", "greater than zero"),
        ("NormalDistribution(mu=1, standardDeviation=1)", "parameters of"),
    ],
    ids=["unknown", "missing", "non-numeric", "too-many", "negative", "unknown-key"],
)
def test_bad_distribution_is_an_error(text: str, allowed: str) -> None:
    result = load_process(activity_eas=ea("Duration", text))
    [error] = result.errors
    assert error.code == "bad-directive" and error.location.line == 2
    assert allowed in f"{error.message} {error.hint}"


def test_unknown_directive_is_a_warning_listing_known_ones() -> None:
    result = load_process(process_eas=ea("Perod", "PT1S"))
    [warning] = result.diagnostics
    assert warning.severity is Severity.WARNING and warning.code == "unknown-directive"
    assert "opspec:Period" in warning.hint


def test_activity_directive_on_a_process_is_unknown_there() -> None:
    result = load_process(process_eas=ea("AutoRun", "false"))
    assert [d.code for d in result.diagnostics] == ["unknown-directive"]


def builtin(xml: str) -> LoadResult:
    return load_process(activity_eas=f'<ExtendedAttribute Name="opspec:BuiltIn">{xml}</ExtendedAttribute>')


def test_arbiter_inputs_keep_priority_order() -> None:
    built = activity(builtin('<opspec:Arbiter Output="motor"><opspec:Input Ref="avoid"/>'
                             '<opspec:Input Ref="wander"/></opspec:Arbiter>')).coordination
    assert built is not None and built.kind is CoordinationKind.ARBITER
    assert built.inputs == ("avoid", "wander") and built.output == "motor"


@pytest.mark.parametrize(
    ("xml", "kind", "fields"),
    [
        (('<opspec:Voter Output="cmd" Options="forward left right stop"><opspec:Input Ref="a"/>'
         '<opspec:Input Ref="b"/></opspec:Voter>'), CoordinationKind.VOTER,
         {"options": ("forward", "left", "right", "stop"), "inputs": ("a", "b")}),
        (('<opspec:Superposition Output="v"><opspec:Input Ref="a" Weight="0.7"/>'
         '<opspec:Input Ref="b"/></opspec:Superposition>'), CoordinationKind.SUPERPOSITION,
         {"weights": (0.7, 1.0), "output": "v"}),
        ('<opspec:PushData Channel="range" Ref="distance"/>', CoordinationKind.PUSH_DATA,
         {"channel": "range", "inputs": ("distance",)}),
        ('<opspec:PullData Channel="range" Ref="distance"/>', CoordinationKind.PULL_DATA,
         {"channel": "range", "output": "distance"}),
        ('<opspec:ModeChange To="search"/>', CoordinationKind.MODE_CHANGE, {"target_mode": "search"}),
    ],
    ids=["voter", "superposition", "push", "pull", "mode-change"],
)
def test_coordination_built_ins(xml: str, kind: CoordinationKind, fields: dict[str, object]) -> None:
    built = activity(builtin(xml)).coordination
    assert built is not None and built.kind is kind
    for key, value in fields.items():
        assert getattr(built, key) == value


@pytest.mark.parametrize(
    "xml",
    ['<opspec:Arbiter Output="m"/>', '<opspec:Arbiter><opspec:Input Ref="a"/></opspec:Arbiter>',
     '<opspec:Juggler/>', '<opspec:PushData Ref="x"/>',
     '<opspec:Superposition Output="v"><opspec:Input Ref="a" Weight="lots"/></opspec:Superposition>'],
    ids=["no-inputs", "no-output", "unknown", "no-channel", "bad-weight"],
)
def test_bad_built_in_is_an_error(xml: str) -> None:
    result = builtin(xml)
    [error] = result.errors
    assert error.code == "bad-built-in" and error.location.line == 2


def package_with(eas: str) -> LoadResult:
    return parse_bytes(f"{HEAD}<ExtendedAttributes>{eas}</ExtendedAttributes></Package>".encode(),
                       path="m.xpdl")


def test_metrics_and_modes() -> None:
    result = package_with(
        '<ExtendedAttribute Name="opspec:Metrics">'
        '<opspec:Count Name="due" Event="process.started" Process="notify"/>'
        '<opspec:Duration Name="lat" Unit="s"><opspec:From Event="activity.started" Activity="a" Which="last"/>'
        '<opspec:To Event="activity.completed" Activity="b"/></opspec:Duration>'
        '<opspec:Ratio Name="r" Numerator="due" Denominator="due"/></ExtendedAttribute>'
        '<ExtendedAttribute Name="opspec:Modes"><opspec:Mode Id="search" Initial="true" Workflows="guide propel"/>'
        '<opspec:Mode Id="dock" Workflows="dock" Source="docking.xpdl"/></ExtendedAttribute>')
    assert result.ok, [str(d) for d in result.diagnostics]
    assert result.package is not None
    count, duration, ratio = result.package.metrics
    assert count.kind is MetricKind.COUNT and count.select is not None and count.select.process == "notify"
    assert duration.start is not None and duration.start.which == "last" and duration.unit == "s"
    assert ratio.numerator == "due"
    search, dock = result.package.modes
    assert search.initial and search.workflows == ("guide", "propel")
    assert dock.source == "docking.xpdl" and not dock.initial


@pytest.mark.parametrize(
    ("xml", "code"),
    [
        ('<ExtendedAttribute Name="opspec:Metrics"><opspec:Count Event="x"/></ExtendedAttribute>', "bad-metric"),
        ('<ExtendedAttribute Name="opspec:Metrics"><opspec:Duration Name="d"/></ExtendedAttribute>', "bad-metric"),
        (('<ExtendedAttribute Name="opspec:Metrics"><opspec:Count Name="c" Event="e" Which="middle"/>'
         "</ExtendedAttribute>"), "bad-metric"),
        ('<ExtendedAttribute Name="opspec:Modes"><opspec:Mode Workflows="a"/></ExtendedAttribute>', "bad-mode"),
        (('<ExtendedAttribute Name="opspec:Modes"><opspec:Mode Id="a" Initial="true"/>'
         '<opspec:Mode Id="b" Initial="true"/></ExtendedAttribute>'), "bad-mode"),
    ],
    ids=["count-no-name", "duration-no-ends", "bad-which", "mode-no-id", "two-initial"],
)
def test_bad_metrics_and_modes_are_errors(xml: str, code: str) -> None:
    result = package_with(xml)
    assert [d.code for d in result.errors] == [code]
    assert result.errors[0].location.line == 2


DOC = Path(__file__).resolve().parents[2] / "docs" / "sisarl-xpdl.md"


def test_complete_example_in_the_documentation_loads_cleanly() -> None:
    text = DOC.read_text(encoding="utf-8")
    start = text.index("## A complete example")
    block = text[text.index("```xml\n", start) + len("```xml\n"):]
    block = block[: block.index("```")]
    result = parse_bytes(block.encode(), path="docs/sisarl-xpdl.md")
    assert result.ok and not result.diagnostics, [str(d) for d in result.diagnostics]
    assert result.package is not None
    guide = result.package.process("guide")
    assert guide is not None and guide.directives.period == pytest.approx(0.1)
    propel = result.package.process("propel")
    assert propel is not None and propel.directives.period == pytest.approx(0.05)
    arbiter = guide.activity("arbitrate")
    assert arbiter is not None and arbiter.coordination is not None
    assert [m.id for m in result.package.modes] == ["clean", "dock"]


@pytest.mark.parametrize(("value", "seconds"), [("PT10M", 600.0), ("PT1H30M", 5400.0),
                                                 ("90", 90.0)], ids=["minutes", "h+min", "seconds"])
def test_run_length_is_the_length_of_one_run(value: str, seconds: float) -> None:
    result = package_with(ea("RunLength", value))
    assert result.ok, [str(d) for d in result.diagnostics]
    assert result.package is not None and result.package.run_length == seconds


@pytest.mark.parametrize("value", ["soon", "PT0S", "-5"], ids=["words", "zero", "negative"])
def test_bad_run_length_is_an_error_naming_the_line(value: str) -> None:
    result = package_with(ea("RunLength", value))
    assert [d.code for d in result.errors] == ["bad-directive"]
    error = result.errors[0]
    assert error.location.line == 2 and "RunLength" in error.message and error.hint


def test_run_length_survives_writing_and_reading_back() -> None:
    from opspec.xpdl.writer import write_xpdl

    result = package_with(ea("RunLength", "PT75M"))
    assert result.package is not None
    again = parse_bytes(write_xpdl(result.package), path="w.xpdl")
    assert again.package is not None and again.package.run_length == 4500.0


@pytest.mark.parametrize("where", ["process", "activity"])
def test_element_with_thousands_of_attributes_is_refused_at_its_line(where: str) -> None:
    # attrib.items() is quadratic in lxml: 200,000 attributes used to hang the loader
    many = "".join(f' x{i}="1"' for i in range(5000))
    result = (load_process(attrs=many) if where == "process"
              else load_process(activity_attrs=many))
    errors = [d for d in result.diagnostics if d.code == "too-many-attributes"]
    assert len(errors) == 1 and errors[0].location.line == 2
    assert "5,002 attributes" in errors[0].message or "5,001 attributes" in errors[0].message
    assert "\n" not in str(errors[0])


def test_opspec_attributes_under_the_limit_are_all_read() -> None:
    filler = "".join(f' x{i}="1"' for i in range(500))
    result = load_process(attrs=f' opspec:Priority="3"{filler}',
                          activity_attrs=f'{filler} opspec:AutoRun="true"')
    assert not result.errors, [str(d) for d in result.diagnostics]
    assert process(result).directives.priority == 3
    assert activity(result).directives.auto_run is True
