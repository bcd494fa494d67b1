"""Simulation parameters as modellers write them — BPSim 2.0 (WfMC) and QBP (BIMP, Apromore,
Simod) — give the durations of tasks and the arrivals of cases, as opspec:Duration and
opspec:Arrival do; what opspec cannot map is a warning at its line, never dropped in silence.

The expected numbers are worked by hand and every run is seeded:

- arrivals with exponential inter-arrival times of mean m over a time T: the first case when
  the run starts, then a Poisson process of rate 1/m, so the count is 1 + Poisson(T/m); the
  tests accept counts in the two-sided 99.9 % range of that law (scipy), and a share of gaps
  shorter than the mean of 1 - e^-1 = 63.2 % (binomial range), which only an exponential law
  gives (a fixed gap gives 0 %);
- a fixed duration gives every cycle exactly that time;
- a normal duration's sample mean lies in the 99.9 % t interval around the declared mean;
- a cycle through a branch taken with probability p adds p times that branch's mean time.

Sources of the rules: BPSim, as Cardanit's BPSim reference states it — "Inter trigger timer
defines the time interval between consecutive occurrences of the start event" and "Trigger
count defines the maximum number of times the start event will trigger" —; QBP as Prosimos's
QBP reader reads it: "The time_tables produced by bimp always have the parameters in seconds,
although it shows other time units in the XML file" (EXPONENTIAL: ``arg1`` the mean; NORMAL:
``arg1`` the standard deviation; GAMMA and LOGNORMAL: ``arg1`` the variance).
"""

from __future__ import annotations

import math
import statistics
from collections import Counter
from pathlib import Path

import pytest
from scipy.stats import binom, chi2, poisson, t

import opspec
from opspec.errors import Severity
from opspec.model import DeclaredDistribution
from opspec.xpdl import load_package
from opspec.xpdl.validate import validate_spec
from opspec.xpdl.writer import write_xpdl

DATA = Path(__file__).parent / "data" / "simulation"
CLINIC = DATA / "bpsim_clinic.bpmn"
LOAN = DATA / "qbp_loan.bpmn"
MIN = 60.0

BPSIM_NS = "http://www.bpsim.org/schemas/2.0"


def _bpsim(scenario: str, *, start: str = "", task: str = "<bpmn:task id=\"work\"/>",
           process_extra: str = "") -> str:
    """One start event, one task, one end event; ``scenario`` the BPSim scenario's body."""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:bpsim="{BPSIM_NS}" xmlns:opspec="urn:opspec:sisarl:1" id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">{process_extra}
    <bpmn:startEvent id="start">{start}</bpmn:startEvent>
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="work"/>
    {task}
    <bpmn:sequenceFlow id="f2" sourceRef="work" targetRef="end"/>
    <bpmn:endEvent id="end"/>
  </bpmn:process>
  <bpmn:relationship type="BPSimData">
    <bpmn:extensionElements>
      <bpsim:BPSimData>
        <bpsim:Scenario id="s1" name="Scenario">
{scenario}
        </bpsim:Scenario>
      </bpsim:BPSimData>
    </bpmn:extensionElements>
    <bpmn:source>d</bpmn:source>
    <bpmn:target>d</bpmn:target>
  </bpmn:relationship>
</bpmn:definitions>
"""


def _element(ref: str, body: str) -> str:
    return f'<bpsim:ElementParameters elementRef="{ref}">{body}</bpsim:ElementParameters>'


def _processing(value: str) -> str:
    return _element("work", "<bpsim:TimeParameters><bpsim:ProcessingTime>"
                    f"{value}</bpsim:ProcessingTime></bpsim:TimeParameters>")


def _arrivals(value: str, count: str = "") -> str:
    counted = (f"<bpsim:TriggerCount><bpsim:NumericParameter value=\"{count}\"/>"
               "</bpsim:TriggerCount>" if count else "")
    return _element("start", "<bpsim:ControlParameters><bpsim:InterTriggerTimer>"
                    f"{value}</bpsim:InterTriggerTimer>{counted}</bpsim:ControlParameters>")


def _write(tmp_path: Path, text: str, name: str = "diagram.bpmn") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _starts_and_cycles(path: Path, until: float, seed: int = 7
                       ) -> tuple[list[float], list[float], list[str | None]]:
    """Arrival times, cycle times of the completed instances, and the start triggers."""
    outcome = opspec.run(path, seed=seed, until=until)
    started = {e.instance: e.time for e in outcome.trace if e.kind == "process.started"}
    triggers = [e.data.get("trigger") for e in outcome.trace if e.kind == "process.started"]
    cycles = [e.time - started[e.instance] for e in outcome.trace
              if e.kind == "process.completed"]
    return sorted(started.values()), cycles, triggers


def _durations(path: Path, activity: str, until: float, seed: int = 7) -> list[float]:
    outcome = opspec.run(path, seed=seed, until=until)
    began: dict[int | None, float] = {}
    out: list[float] = []
    for event in outcome.trace:
        if event.activity != activity:
            continue
        if event.kind == "activity.started":
            began[event.instance] = event.time
        elif event.kind == "activity.completed" and event.instance in began:
            out.append(event.time - began.pop(event.instance))
    return out


def _codes(path: Path, code: str) -> list[tuple[Severity, int | None, str]]:
    _package, report = validate_spec(path)
    return [(d.severity, d.location.line, d.message) for d in report.diagnostics
            if d.code == code]


def _line_of(path: Path, needle: str) -> int:
    """The line of ``path`` where ``needle`` first appears (1-based)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    return next(n for n, line in enumerate(lines, 1) if needle in line)


def _t_interval(sample: list[float]) -> tuple[float, float]:
    n = len(sample)
    half = t.ppf(0.9995, n - 1) * statistics.stdev(sample) / math.sqrt(n)
    mean = statistics.fmean(sample)
    return mean - half, mean + half


# -- arrivals ----------------------------------------------------------------------------------

def test_exponential_inter_arrivals_of_mean_10_min_give_about_100_cases_in_1000_min(
        tmp_path: Path) -> None:
    """BPSim's InterTriggerTimer "defines the time interval between consecutive occurrences of
    the start event": exponential gaps of mean 10 min over 1000 min give 1 + Poisson(100)
    cases, and 63.2 % of the gaps are shorter than their mean."""
    path = _write(tmp_path, _bpsim(
        '<bpsim:ScenarioParameters baseTimeUnit="min"/>'
        + _arrivals('<bpsim:NegativeExponentialDistribution mean="10"/>')))
    starts, _cycles, triggers = _starts_and_cycles(path, until=1000 * MIN)
    low, high = poisson.interval(0.999, 100)
    assert low + 1 <= len(starts) <= high + 1
    assert starts[0] == 0.0 and set(triggers) == {"arrival"}
    gaps = [b - a for a, b in zip(starts, starts[1:])]
    short = sum(1 for gap in gaps if gap < 10 * MIN)
    low, high = binom.interval(0.999, len(gaps), 1 - math.exp(-1))
    assert low <= short <= high
    # the mean gap, from the exact law of a sum of n exponential gaps (chi-square, 2n dof)
    n = len(gaps)
    assert (chi2.ppf(0.0005, 2 * n) / (2 * n) * 10 * MIN <= statistics.fmean(gaps)
            <= chi2.ppf(0.9995, 2 * n) / (2 * n) * 10 * MIN)


def test_a_trigger_count_stops_the_arrivals(tmp_path: Path) -> None:
    """BPSim's TriggerCount "defines the maximum number of times the start event will
    trigger": 12 arrivals, 5 min apart, then none although the run goes on."""
    path = _write(tmp_path, _bpsim(
        '<bpsim:ScenarioParameters baseTimeUnit="min"/>'
        + _arrivals('<bpsim:FloatingParameter value="5"/>', count="12")))
    starts, _cycles, _triggers = _starts_and_cycles(path, until=1000 * MIN)
    assert starts == [k * 5 * MIN for k in range(12)]


def test_qbp_arrivals_are_seconds_and_stop_at_process_instances() -> None:
    """QBP: the arrival rate's ``arg1`` is the mean gap in seconds (600 s, though the file
    shows minutes), and ``processInstances="200"`` cases arrive in all."""
    starts, _cycles, triggers = _starts_and_cycles(LOAN, until=30 * 86_400.0)
    assert len(starts) == 200 and set(triggers) == {"arrival"}
    gaps = [b - a for a, b in zip(starts, starts[1:])]
    n = len(gaps)
    assert (chi2.ppf(0.0005, 2 * n) / (2 * n) * 600 <= statistics.fmean(gaps)
            <= chi2.ppf(0.9995, 2 * n) / (2 * n) * 600)


def test_arrivals_are_the_same_for_a_seed_whatever_else_the_run_draws(tmp_path: Path) -> None:
    """The arrivals draw from their own stream: giving the task a random duration does not
    move a single arrival; another seed does."""
    arrivals = _arrivals('<bpsim:NegativeExponentialDistribution mean="10"/>')
    unit = '<bpsim:ScenarioParameters baseTimeUnit="min"/>'
    plain = _write(tmp_path, _bpsim(unit + arrivals), "plain.bpmn")
    timed = _write(tmp_path, _bpsim(unit + arrivals + _processing(
        '<bpsim:UniformDistribution min="1" max="9"/>')), "timed.bpmn")
    first = _starts_and_cycles(plain, until=300 * MIN, seed=3)[0]
    assert first == _starts_and_cycles(timed, until=300 * MIN, seed=3)[0]
    assert first != _starts_and_cycles(plain, until=300 * MIN, seed=4)[0]


def test_arrivals_at_a_timer_start_event_are_not_read_and_said_at_their_line(
        tmp_path: Path) -> None:
    """A start event with its own trigger is started by it, not by the BPSim arrivals."""
    timer = ("<bpmn:timerEventDefinition><bpmn:timeCycle>R3/PT1H</bpmn:timeCycle>"
             "</bpmn:timerEventDefinition>")
    path = _write(tmp_path, _bpsim('<bpsim:ScenarioParameters baseTimeUnit="min"/>'
                                   + _arrivals('<bpsim:FloatingParameter value="5"/>'),
                                   start=timer))
    warnings = _codes(path, "unread-simulation-parameter")
    assert [(s, line) for s, line, m in warnings if "own trigger" in m] == [
        (Severity.WARNING, _line_of(path, 'elementRef="start"'))]
    starts, _cycles, _triggers = _starts_and_cycles(path, until=10 * 3600.0)
    assert starts == [3600.0, 7200.0, 10800.0]       # the timer's R3/PT1H


# -- durations ---------------------------------------------------------------------------------

@pytest.mark.parametrize("value", [
    '<bpsim:FloatingParameter value="5"/>',
    '<bpsim:NumericParameter value="5"/>',
    '<bpsim:DurationParameter value="PT5M"/>',
])
def test_a_fixed_5_minute_task_gives_cycle_times_of_exactly_5_min(tmp_path: Path,
                                                                   value: str) -> None:
    """A constant processing time in minutes (or an ISO 8601 duration, whatever the unit)
    makes every case take exactly 5 minutes."""
    path = _write(tmp_path, _bpsim('<bpsim:ScenarioParameters baseTimeUnit="min"/>'
                                   + _arrivals('<bpsim:FloatingParameter value="7"/>')
                                   + _processing(value)))
    _starts, cycles, _triggers = _starts_and_cycles(path, until=200 * MIN)
    assert len(cycles) >= 28 and cycles == pytest.approx([300.0] * len(cycles))


def test_without_a_base_time_unit_bpsim_times_are_milliseconds_said_at_the_line(
        tmp_path: Path) -> None:
    """BPSim's ScenarioParameters baseTimeUnit defaults to ms: 5000 is 5 seconds."""
    path = _write(tmp_path, _bpsim("<bpsim:ScenarioParameters/>"
                                   + _arrivals('<bpsim:FloatingParameter value="60000"/>')
                                   + _processing('<bpsim:FloatingParameter value="5000"/>')))
    assert [(s, line) for s, line, _m in _codes(path, "bpsim-time-unit")] == [
        (Severity.INFO, _line_of(path, "<bpsim:ScenarioParameters/>"))]
    _starts, cycles, _triggers = _starts_and_cycles(path, until=10 * MIN)
    assert set(cycles) == {5.0}


def test_a_normal_processing_time_has_its_declared_mean_and_spread(tmp_path: Path) -> None:
    """NormalDistribution mean=20 standardDeviation=4 (minutes): the sample mean lies in its
    99.9 % t interval around 20 min, the variance in its chi-square interval around 16."""
    path = _write(tmp_path, _bpsim(
        '<bpsim:ScenarioParameters baseTimeUnit="min"/>'
        + _arrivals('<bpsim:FloatingParameter value="1"/>')
        + _processing('<bpsim:NormalDistribution mean="20" standardDeviation="4"/>')))
    sample = [d / MIN for d in _durations(path, "work", until=500 * MIN)]
    n = len(sample)
    assert n >= 450
    low, high = _t_interval(sample)
    assert low <= 20.0 <= high
    ratio = (n - 1) * statistics.variance(sample) / 16.0
    assert chi2.ppf(0.0005, n - 1) <= ratio <= chi2.ppf(0.9995, n - 1)


def test_the_clinic_runs_as_its_bpsim_scenario_says() -> None:
    """Check-in 5 min, then 25 % see the nurse for 20 min on average: a cycle takes
    5 + 0.25 × 20 = 10 min on average; the nurse is seen by a Binomial(n, 0.25) count."""
    outcome = opspec.run(CLINIC, seed=11, until=6000 * MIN)
    started = {e.instance: e.time for e in outcome.trace if e.kind == "process.started"}
    cycles = [(e.time - started[e.instance]) / MIN for e in outcome.trace
              if e.kind == "process.completed"]
    branches = Counter(e.data["flow"] for e in outcome.trace if e.kind == "branch.chosen")
    n = sum(branches.values())
    assert n >= 500
    low, high = binom.interval(0.999, n, 0.25)
    assert low <= branches["nurse_yes"] <= high
    low, high = _t_interval(cycles)
    assert low <= 10.0 <= high
    assert min(cycles) == pytest.approx(5.0)


def test_the_qbp_loan_model_runs_as_its_simulation_info_says() -> None:
    """Check 300 s (FIXED), then 70 % are assessed, UNIFORM 600–1200 s (mean 900 s): a cycle
    takes 300 + 0.7 × 900 = 930 s on average, between 300 s and 1500 s."""
    _starts, cycles, _triggers = _starts_and_cycles(LOAN, until=30 * 86_400.0, seed=5)
    assert len(cycles) == 200
    low, high = _t_interval(cycles)
    assert low <= 930.0 <= high
    assert min(cycles) == pytest.approx(300.0) and max(cycles) <= 1500.0 + 1e-6


# -- how each distribution is read ---------------------------------------------------------------

@pytest.mark.parametrize(("value", "kind", "parameters"), [
    ('<bpsim:FloatingParameter value="2"/>', "ConstantParameter", (("value", 120.0),)),
    ('<bpsim:NormalDistribution mean="10" standardDeviation="2"/>', "NormalDistribution",
     (("mean", 600.0), ("standardDeviation", 120.0))),
    ('<bpsim:LogNormalDistribution mean="10" standardDeviation="2"/>', "LogNormalDistribution",
     (("mean", 600.0), ("standardDeviation", 120.0))),
    ('<bpsim:UniformDistribution min="1" max="3"/>', "UniformDistribution",
     (("min", 60.0), ("max", 180.0))),
    ('<bpsim:TriangularDistribution min="1" mode="2" max="4"/>', "TriangularDistribution",
     (("min", 60.0), ("mode", 120.0), ("max", 240.0))),
    ('<bpsim:NegativeExponentialDistribution mean="3"/>', "ExponentialDistribution",
     (("mean", 180.0),)),
    ('<bpsim:GammaDistribution shape="2" scale="3"/>', "GammaDistribution",
     (("shape", 2.0), ("scale", 180.0))),
    # Erlang(k = 3, mean = 6 min) is the gamma law of shape 3 and scale 6/3 = 2 min
    ('<bpsim:ErlangDistribution k="3" mean="6"/>', "GammaDistribution",
     (("shape", 3.0), ("scale", 120.0))),
    ('<bpsim:TruncatedNormalDistribution mean="5" standardDeviation="1" min="4" max="7"/>',
     "TruncatedNormalDistribution", (("mean", 300.0), ("standardDeviation", 60.0),
                                     ("min", 240.0), ("max", 420.0))),
    ('<bpsim:WeibullDistribution shape="1.5" scale="4"/>', "WeibullDistribution",
     (("shape", 1.5), ("scale", 240.0))),
])
def test_each_bpsim_distribution_becomes_the_duration_opspec_duration_would_give(
        tmp_path: Path, value: str, kind: str, parameters: tuple[tuple[str, float], ...]
        ) -> None:
    """Times scale by the base time unit (here min: × 60); shapes do not."""
    path = _write(tmp_path, _bpsim('<bpsim:ScenarioParameters baseTimeUnit="min"/>'
                                   + _processing(value)))
    assert _task_duration(path) == DeclaredDistribution(kind=kind, parameters=parameters)


@pytest.mark.parametrize(("attributes", "kind", "parameters"), [
    ('type="FIXED" mean="300" arg1="0" arg2="0"', "ConstantParameter", (("value", 300.0),)),
    ('type="NORMAL" mean="600" arg1="60" arg2="0"', "NormalDistribution",
     (("mean", 600.0), ("standardDeviation", 60.0))),
    ('type="EXPONENTIAL" mean="0" arg1="450" arg2="0"', "ExponentialDistribution",
     (("mean", 450.0),)),
    ('type="UNIFORM" mean="3600" arg1="240" arg2="540"', "UniformDistribution",
     (("min", 240.0), ("max", 540.0))),
    ('type="TRIANGULAR" mean="300" arg1="100" arg2="800"', "TriangularDistribution",
     (("min", 100.0), ("mode", 300.0), ("max", 800.0))),
    # variance 3600 s²: standard deviation 60 s
    ('type="LOGNORMAL" mean="600" arg1="3600" arg2="0"', "LogNormalDistribution",
     (("mean", 600.0), ("standardDeviation", 60.0))),
    # mean 600 s, variance 120000 s²: shape 600²/120000 = 3, scale 120000/600 = 200 s
    ('type="GAMMA" mean="600" arg1="120000" arg2="0"', "GammaDistribution",
     (("shape", 3.0), ("scale", 200.0))),
])
def test_each_qbp_distribution_becomes_the_duration_opspec_duration_would_give(
        tmp_path: Path, attributes: str, kind: str, parameters: tuple[tuple[str, float], ...]
        ) -> None:
    """QBP values are seconds, whatever qbp:timeUnit shows (here: hours)."""
    text = LOAN.read_text(encoding="utf-8").replace(
        'type="FIXED" mean="300" arg1="0" arg2="0"', attributes).replace(
        "<qbp:timeUnit>minutes</qbp:timeUnit>", "<qbp:timeUnit>hours</qbp:timeUnit>")
    path = _write(tmp_path, text)
    assert _task_duration(path, "check") == DeclaredDistribution(kind=kind,
                                                                  parameters=parameters)


def _task_duration(path: Path, task: str = "work") -> DeclaredDistribution | None:
    result = load_package(path)
    assert result.package is not None
    activity = next(a for p in result.package.processes for a in p.all_activities()
                    if a.id == task)
    return activity.directives.duration


# -- what wins, what is not read ----------------------------------------------------------------

def test_the_tasks_own_opspec_duration_wins_over_bpsim(tmp_path: Path) -> None:
    task = ('<bpmn:task id="work"><bpmn:extensionElements><opspec:Duration>PT2M'
            "</opspec:Duration></bpmn:extensionElements></bpmn:task>")
    path = _write(tmp_path, _bpsim('<bpsim:ScenarioParameters baseTimeUnit="min"/>'
                                   + _processing('<bpsim:FloatingParameter value="5"/>'),
                                   task=task))
    assert _task_duration(path) == DeclaredDistribution(kind="ConstantParameter",
                                                        parameters=(("value", 120.0),))
    assert [s for s, _line, _m in _codes(path, "duration-given-twice")] == [Severity.INFO]


def test_what_opspec_cannot_map_is_a_warning_at_its_line_and_the_run_does_without(
        tmp_path: Path) -> None:
    """A Poisson law counts events, it is no time: a warning at its line, and the task runs
    at once; resource and cost parameters are said once per kind, at the first line."""
    scenario = ('<bpsim:ScenarioParameters baseTimeUnit="min"/>\n'
                + _arrivals('<bpsim:FloatingParameter value="10"/>') + "\n"
                + _element("work", "<bpsim:TimeParameters><bpsim:ProcessingTime>\n"
                           '<bpsim:PoissonDistribution mean="4"/>\n'
                           "</bpsim:ProcessingTime></bpsim:TimeParameters>\n"
                           "<bpsim:CostParameters><bpsim:FixedCost>"
                           '<bpsim:FloatingParameter value="3"/></bpsim:FixedCost>'
                           "</bpsim:CostParameters>"))
    path = _write(tmp_path, _bpsim(scenario))
    found = {(line, "PoissonDistribution" in m, "CostParameters" in m)
             for s, line, m in _codes(path, "unread-simulation-parameter")
             if s is Severity.WARNING}
    assert found == {(_line_of(path, "PoissonDistribution"), True, False),
                     (_line_of(path, "CostParameters"), False, True)}
    _starts, cycles, _triggers = _starts_and_cycles(path, until=60 * MIN)
    assert set(cycles) == {0.0}


def test_a_processing_time_on_a_gateway_or_an_unknown_id_is_ignored_and_said(
        tmp_path: Path) -> None:
    scenario = (_element("f1", "<bpsim:TimeParameters><bpsim:ProcessingTime>"
                         '<bpsim:FloatingParameter value="5"/></bpsim:ProcessingTime>'
                         "</bpsim:TimeParameters>")
                + "\n" + _element("nowhere", "<bpsim:TimeParameters><bpsim:ProcessingTime>"
                                  '<bpsim:FloatingParameter value="5"/></bpsim:ProcessingTime>'
                                  "</bpsim:TimeParameters>"))
    path = _write(tmp_path, _bpsim(scenario))
    assert any("sequenceFlow 'f1'" in m for _s, _l, m in
               _codes(path, "unread-simulation-parameter"))
    assert any("'nowhere'" in m for _s, _l, m in _codes(path, "unknown-reference"))


def test_arrivals_and_durations_are_written_out_as_opspec_directives_and_read_back(
        tmp_path: Path) -> None:
    """``opspec preprocess``/``compile`` write the model: the BPSim arrivals become
    opspec:Arrival and opspec:ArrivalCount, the processing time opspec:Duration, and the XPDL
    reader reads the same run back."""
    path = _write(tmp_path, _bpsim(
        '<bpsim:ScenarioParameters baseTimeUnit="min"/>'
        + _arrivals('<bpsim:NegativeExponentialDistribution mean="10"/>', count="30")
        + _processing('<bpsim:FloatingParameter value="5"/>')))
    result = load_package(path)
    assert result.package is not None
    xpdl = tmp_path / "written.xpdl"
    xpdl.write_bytes(write_xpdl(result.package))
    text = xpdl.read_text(encoding="utf-8")
    assert 'opspec:Arrival' in text and 'opspec:ArrivalCount' in text
    again = load_package(xpdl)
    assert again.package is not None and not [d for d in again.diagnostics
                                              if d.severity is Severity.ERROR]
    bpmn_run = _starts_and_cycles(path, until=1000 * MIN, seed=2)
    xpdl_run = _starts_and_cycles(xpdl, until=1000 * MIN, seed=2)
    assert len(bpmn_run[0]) == 30
    assert bpmn_run[:2] == xpdl_run[:2]


def test_the_scenario_duration_is_the_run_length(tmp_path: Path) -> None:
    """BPSim's ScenarioParameters Duration says how long the simulation runs: arrivals every
    10 min over a scenario of 2 hours (in the base unit, min) are 12 cases, at 0 … 110 min."""
    scenario = ('<bpsim:ScenarioParameters baseTimeUnit="min"><bpsim:Duration>'
                '<bpsim:FloatingParameter value="120"/></bpsim:Duration>'
                "</bpsim:ScenarioParameters>"
                + _arrivals('<bpsim:FloatingParameter value="10"/>'))
    path = _write(tmp_path, _bpsim(scenario))
    result = load_package(path)
    assert result.package is not None and result.package.run_length == 7200.0
    outcome = opspec.run(path, seed=1)                 # no length given: the scenario's
    assert len([e for e in outcome.trace if e.kind == "process.started"]) == 12


def test_a_scenario_with_probabilities_only_says_nothing_about_time_units(
        tmp_path: Path) -> None:
    scenario = _element("f1", "<bpsim:ControlParameters><bpsim:Probability>"
                        '<bpsim:FloatingParameter value="1"/></bpsim:Probability>'
                        "</bpsim:ControlParameters>")
    path = _write(tmp_path, _bpsim("<bpsim:ScenarioParameters/>" + scenario))
    assert not _codes(path, "bpsim-time-unit")


def test_arrivals_into_a_process_with_two_start_events_are_said_to_start_both(
        tmp_path: Path) -> None:
    """opspec starts a process, and so every start event of it: BPSim meant one."""
    text = _bpsim('<bpsim:ScenarioParameters baseTimeUnit="min"/>'
                  + _arrivals('<bpsim:FloatingParameter value="10"/>'),
                  process_extra='\n    <bpmn:startEvent id="other"/>')
    path = _write(tmp_path, text)
    assert any("2 start events" in m for _s, _l, m in
               _codes(path, "unread-simulation-parameter"))


def test_result_requests_beside_a_value_do_not_hide_it(tmp_path: Path) -> None:
    """BPSim lets a parameter hold result requests (statistics asked of the simulator) beside
    its value, as Trisotech and Cardanit write them: the value is read, the requests are said
    once, as an info."""
    path = _write(tmp_path, _bpsim('<bpsim:ScenarioParameters baseTimeUnit="min"/>'
                                   + _processing("<bpsim:ResultRequest>mean</bpsim:ResultRequest>"
                                                 '<bpsim:FloatingParameter value="5"/>')))
    assert _task_duration(path) == DeclaredDistribution(kind="ConstantParameter",
                                                        parameters=(("value", 300.0),))
    said = _codes(path, "unread-simulation-parameter")
    assert [(s, "ResultRequest" in m) for s, _l, m in said] == [(Severity.INFO, True)]


@pytest.mark.parametrize(("attributes", "said"), [
    ('type="EXPONENTIAL" mean="0" arg1="0" arg2="0"', "mean must be > 0"),
    ('type="HISTOGRAM" mean="600" arg1="0" arg2="0"', "'HISTOGRAM'"),
    ('type="GAMMA" mean="600" arg1="0" arg2="0"', "arg1 (the variance)"),
    ('type="NORMAL" mean="six hundred" arg1="60" arg2="0"', "'six hundred' is not a number"),
])
def test_qbp_arrivals_opspec_cannot_draw_are_said_and_not_run(
        tmp_path: Path, attributes: str, said: str) -> None:
    text = LOAN.read_text(encoding="utf-8").replace(
        'type="EXPONENTIAL" mean="0" arg1="600" arg2="0"', attributes)
    path = _write(tmp_path, text)
    warnings = [(line, m) for s, line, m in _codes(path, "unread-simulation-parameter")
                if s is Severity.WARNING and said in m]
    assert [line for line, _m in warnings] == [_line_of(path, "arrivalRateDistribution")]
    starts, _cycles, triggers = _starts_and_cycles(path, until=86_400.0)
    assert triggers == ["auto"]             # no arrivals: the process starts once, as drawn


def test_an_inter_trigger_time_of_0_is_refused_rather_than_run(tmp_path: Path) -> None:
    """Arrivals 0 apart would start instances without end at one instant."""
    path = _write(tmp_path, _bpsim('<bpsim:ScenarioParameters baseTimeUnit="min"/>'
                                   + _arrivals('<bpsim:FloatingParameter value="0"/>')))
    assert any("inter-arrival time is 0" in m for _s, _l, m in
               _codes(path, "unread-simulation-parameter"))
    assert _starts_and_cycles(path, until=600.0)[2] == ["auto"]


def test_qbp_resources_and_a_working_timetable_are_said_at_their_lines(tmp_path: Path) -> None:
    """BIMP and Prosimos make a case wait while every resource is busy and work only within
    a timetable; opspec reads neither. Measured with Prosimos on this model (1000 cases):
    2 clerks instead of 50 raise the mean cycle time from 929 s to 1887 s, a 09:00-17:00
    weekday timetable to 55 706 s, so each is a warning at its own line; a 24/7 timetable
    changes nothing and is not named."""
    said = [(line, m) for s, line, m in _codes(LOAN, "unread-simulation-parameter")
            if s is Severity.WARNING]
    assert said == [(_line_of(LOAN, "<qbp:resources>"), said[0][1])]
    assert "50 'Clerk'" in said[0][1] and "wait while every one is busy" in said[0][1]
    office = _write(tmp_path, LOAN.read_text(encoding="utf-8").replace(
        'fromTime="00:00:00.000+00:00" toTime="23:59:59.999+00:00"',
        'fromTime="09:00:00.000+00:00" toTime="17:00:00.000+00:00"').replace(
        'toWeekDay="SUNDAY"', 'toWeekDay="FRIDAY"'))
    timetable = [(line, m) for s, line, m in _codes(office, "unread-simulation-parameter")
                 if s is Severity.WARNING and "timetable" in m]
    assert [line for line, _m in timetable] == [_line_of(office, "<qbp:timetable ")]
    assert "MONDAY-FRIDAY 09:00-17:00" in timetable[0][1]
