"""Simulation parameters as process-simulation tools write them into a BPMN file.

A diagram drawn for people leaves out what a simulation needs: which branch of an undecided
gateway, how long a task takes, how often a case arrives. Simulation tools attach these to the
diagram in one of two common forms, both read here into the model opspec's own directives
give (``opspec:Probability``, ``opspec:Duration``, ``opspec:Arrival``):

- BPSim (WfMC, versions 1.0 and 2.0): ``bpsim:BPSimData/bpsim:Scenario`` (the first scenario,
  BPSim's own default when a tool asks for none), inside a ``bpmn:relationship`` (or any
  ``bpmn:extensionElements``) of the definitions. Its ``bpsim:ElementParameters
  [@elementRef=ID]`` give a flow's ``ControlParameters/Probability``, a task's
  ``TimeParameters/ProcessingTime`` and a start event's ``ControlParameters/InterTriggerTimer``
  and ``TriggerCount``, in the scenario's ``baseTimeUnit`` (BPSim's default: ms).
- QBP, the format of BIMP, Apromore and Simod: ``qbp:processSimulationInfo`` with its
  ``qbp:sequenceFlow[@elementId]/@executionProbability``, ``qbp:element[@elementId]/
  qbp:durationDistribution``, ``qbp:arrivalRateDistribution`` and ``processInstances``.

An element's own opspec directive wins over both; BPSim wins over QBP. What opspec does not
read (resources, costs, calendars, queue and set-up times…) is a located warning
(``unread-simulation-parameter``), never dropped in silence. The values themselves are read by
:mod:`.sim_values`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Final

from lxml import etree

from opspec.model.sisarl import DeclaredDistribution
from opspec.xpdl.bpmn.common import BPMN, Defs, local, namespace
from opspec.xpdl.bpmn.sim_values import (
    BPSIM_TIME_UNITS,
    UNREAD,
    bpsim_count,
    bpsim_distribution,
    bpsim_values,
    qbp_distribution,
)
from opspec.xpdl.sisarl_values import parse_probability

__all__ = ["BPSIM_NAMESPACES", "QBP", "TIMED", "SimulationParameters",
           "read_simulation_parameters"]

BPSIM_NAMESPACES: Final = frozenset({"http://www.bpsim.org/schemas/1.0",
                                     "http://www.bpsim.org/schemas/2.0"})
QBP: Final = "http://www.qbp-simulator.com/Schema201212"
#: The BPMN elements a processing time applies to: tasks, which opspec runs for a duration.
TIMED: Final = frozenset({"task", "userTask", "manualTask", "serviceTask", "scriptTask",
                          "sendTask", "receiveTask", "businessRuleTask"})

Arrival = tuple[DeclaredDistribution, int | None, str]


@dataclass(frozen=True, slots=True)
class SimulationParameters:
    """What the file's simulation parameters give, by id, and where each was read (for
    messages): branch probabilities by sequence flow, durations by task, arrivals (the
    inter-arrival time, how many, the source) by process."""

    probabilities: dict[str, float] = field(default_factory=dict)
    source: dict[str, str] = field(default_factory=dict)
    durations: dict[str, DeclaredDistribution] = field(default_factory=dict)
    duration_source: dict[str, str] = field(default_factory=dict)
    arrivals: dict[str, Arrival] = field(default_factory=dict)
    run_length: list[float] = field(default_factory=list)     # BPSim's scenario Duration, if any


def read_simulation_parameters(root: etree._Element, defs: Defs) -> SimulationParameters:
    """The branch probabilities, task durations and arrivals of the file's first BPSim
    scenario and its QBP simulation info."""
    out = SimulationParameters()
    scenario = _first_bpsim_scenario(root)
    if scenario is not None:
        _Bpsim(scenario, defs, out).read()
    for info in root.iter(f"{{{QBP}}}processSimulationInfo"):
        _read_qbp(info, root, defs, out)
        break
    for flow_element in root.iter(f"{{{QBP}}}sequenceFlow"):
        raw = flow_element.get("executionProbability")
        if raw is not None:
            _put(out, defs, flow_element, (flow_element.get("elementId") or "").strip(), raw,
                 "QBP")
    return out


def _first_bpsim_scenario(root: etree._Element) -> etree._Element | None:
    for element in root.iter():
        if (isinstance(element.tag, str) and local(element) == "Scenario"
                and namespace(element) in BPSIM_NAMESPACES):
            return element
    return None


def _children(element: etree._Element) -> list[etree._Element]:
    return [c for c in element if isinstance(c.tag, str)]


class _Bpsim:
    """One BPSim scenario, read into ``out``; what it holds that opspec does not read is
    collected by kind and said once per kind, at its first line."""

    def __init__(self, scenario: etree._Element, defs: Defs, out: SimulationParameters) -> None:
        self.scenario = scenario
        self.defs = defs
        self.out = out
        self.unit = 0.001
        # where the scenario leaves its time unit to BPSim's default (said at the first time)
        self.no_unit: etree._Element | None = scenario
        self.unread: dict[str, list[etree._Element]] = {}

    def read(self) -> None:
        for sub in _children(self.scenario):
            name = local(sub)
            if name == "ScenarioParameters":
                self.scenario_parameters(sub)
        for sub in _children(self.scenario):
            name = local(sub)
            if name == "ElementParameters":
                self.element_parameters(sub)
            elif name != "ScenarioParameters":
                self.unread.setdefault(name, []).append(sub)
        for kind, elements in self.unread.items():
            more = f" (and {len(elements) - 1} more)" if len(elements) > 1 else ""
            if kind == "ResultRequest":
                self.defs.info(elements[0], UNREAD,
                               f"BPSim ResultRequest{more} asks for statistics opspec does not "
                               "compute as such: it reports its own metrics",
                               "declare opspec:Metrics, or use opspec evaluate (docs/"
                               "evaluation.md)")
                continue
            self.defs.ctx.warning(
                elements[0], UNREAD,
                f"BPSim {kind}{more} is not read by opspec: the run does without it",
                "opspec reads branch probabilities, processing times and inter-trigger "
                "timers; see docs/bpmn.md, Simulation parameters")

    def scenario_parameters(self, parameters: etree._Element) -> None:
        raw = parameters.get("baseTimeUnit")
        self.no_unit = parameters
        if raw is not None and raw.strip() in BPSIM_TIME_UNITS:
            self.unit = BPSIM_TIME_UNITS[raw.strip()]
            self.no_unit = None
        elif raw is not None:
            self.no_unit = None
            self.defs.ctx.warning(parameters, UNREAD,
                                  f"BPSim baseTimeUnit {raw!r} is no BPSim time unit; opspec "
                                  "reads the scenario's times in milliseconds",
                                  "write ms, s, min, hour, day or year")
        for sub in _children(parameters):
            if local(sub) == "Duration":
                self.duration(sub)
            else:
                self.unread.setdefault(f"ScenarioParameters/{local(sub)}", []).append(sub)

    def times(self, parameter: etree._Element, what: str) -> DeclaredDistribution | None:
        """``parameter``'s value in seconds; the first time read without a base time unit,
        an info says the numbers are taken as milliseconds (BPSim's default)."""
        values = bpsim_values(parameter)
        if self.no_unit is not None and values and local(values[0]) != "DurationParameter":
            self.defs.info(self.no_unit, "bpsim-time-unit",
                           "the BPSim scenario gives no baseTimeUnit: its times are read in "
                           "milliseconds, BPSim's default", 'set baseTimeUnit="min" (or s, '
                           "hour, day) on bpsim:ScenarioParameters to say what its numbers "
                           "count")
            self.no_unit = None
        return bpsim_distribution(parameter, self.unit, self.defs, what)

    def duration(self, parameter: etree._Element) -> None:
        """The scenario's Duration: how long a run lasts (as opspec:RunLength)."""
        dist = self.times(parameter, "BPSim scenario duration")
        if dist is None:
            return
        if dist.kind != "ConstantParameter" or not dist.parameters or dist.parameters[0][1] <= 0:
            self.defs.ctx.warning(parameter, UNREAD, "BPSim scenario duration: opspec takes a "
                                  "run length from a constant above 0 only; it is not read",
                                  "give a FloatingParameter or a DurationParameter")
            return
        self.out.run_length.append(dist.parameters[0][1])

    def element_parameters(self, parameters: etree._Element) -> None:
        ref = (parameters.get("elementRef") or "").strip()
        target = self.defs.by_id.get(ref)
        timer = count = None
        for group in _children(parameters):
            kind = local(group)
            requests = [r for r in group.iter() if isinstance(r.tag, str)
                        and local(r) == "ResultRequest"]
            if requests:     # asks a simulator for statistics: opspec has its own metrics
                self.unread.setdefault("ResultRequest", []).extend(requests)
            if kind == "ControlParameters":
                for parameter in _children(group):
                    name = local(parameter)
                    if not bpsim_values(parameter):
                        continue                     # result requests only
                    if name == "Probability":
                        self.probability(parameter, ref)
                    elif name == "InterTriggerTimer":
                        timer = parameter
                    elif name == "TriggerCount":
                        count = parameter
                    else:
                        self.unread.setdefault(f"ControlParameters/{name}", []).append(
                            parameter)
            elif kind == "TimeParameters":
                for parameter in _children(group):
                    if not bpsim_values(parameter):
                        continue                     # result requests only
                    if local(parameter) == "ProcessingTime":
                        self.processing_time(parameter, ref, target)
                    else:
                        self.unread.setdefault(f"TimeParameters/{local(parameter)}",
                                               []).append(parameter)
            else:
                self.unread.setdefault(kind, []).append(group)
        if timer is not None or count is not None:
            self.arrival(parameters, ref, target, timer, count)

    def probability(self, parameter: etree._Element, ref: str) -> None:
        for value_element in bpsim_values(parameter):
            if value_element.get("value"):
                _put(self.out, self.defs, value_element, ref, value_element.get("value") or "",
                     "BPSim")
                return

    def processing_time(self, parameter: etree._Element, ref: str,
                        target: etree._Element | None) -> None:
        if not _names_a(target, TIMED, parameter, ref, "a processing time", "task", self.defs):
            return
        what = f"BPSim processing time of {ref!r}"
        dist = self.times(parameter, what)
        if dist is not None:
            self.out.durations.setdefault(ref, dist)
            self.out.duration_source.setdefault(ref, "BPSim")

    def arrival(self, parameters: etree._Element, ref: str, target: etree._Element | None,
                timer: etree._Element | None, count: etree._Element | None) -> None:
        what = f"BPSim arrivals at {ref!r}"
        process = _start_process(target, parameters, ref, self.defs, "BPSim inter-trigger "
                                 "timer")
        if process is None:
            return
        if timer is None:
            self.defs.ctx.warning(count, UNREAD, f"{what}: a TriggerCount without an "
                                  "InterTriggerTimer says how many, not when; opspec does not "
                                  "read it", "give the InterTriggerTimer too")
            return
        dist = self.times(timer, what)
        if dist is None or not _positive_mean(dist, timer, self.defs, what):
            return
        how_many = bpsim_count(count, self.defs, what) if count is not None else None
        self.out.arrivals.setdefault(process, (dist, how_many, "BPSim"))


def _names_a(target: etree._Element | None, kinds: frozenset[str], where: etree._Element,
             ref: str, what: str, noun: str, defs: Defs) -> bool:
    """Whether ``target`` (what ``ref`` names) is a BPMN element of ``kinds``; a warning
    at ``where`` when it is not."""
    if target is None:
        defs.ctx.warning(where, "unknown-reference",
                         f"{what} is given for {ref!r}, which is no element of this file; it "
                         "is ignored", f"name a {noun}'s id")
        return False
    if namespace(target) != BPMN or local(target) not in kinds:
        defs.ctx.warning(where, UNREAD, f"{what} is given for bpmn:{local(target)} {ref!r}; "
                         f"opspec reads it only for a {noun}, so it is ignored",
                         f"give it to a {noun}")
        return False
    return True


def _start_process(target: etree._Element | None, where: etree._Element, ref: str,
                   defs: Defs, what: str) -> str | None:
    """The id of the process a none start event ``target`` starts, or ``None`` with a
    warning when arrivals cannot start there."""
    if not _names_a(target, frozenset({"startEvent"}), where, ref, what, "start event",
                    defs):
        return None
    assert target is not None
    parent = target.getparent()
    if parent is None or local(parent) != "process":
        defs.ctx.warning(where, UNREAD, f"{what} is given for start event {ref!r} of a "
                         f"bpmn:{local(parent) if parent is not None else '?'}; opspec starts "
                         "only a process by arrivals, so it is ignored",
                         "give it to the start event of a process")
        return None
    starts = [c for c in _children(parent) if local(c) == "startEvent"]
    if len(starts) > 1:
        defs.ctx.warning(where, UNREAD, f"{what} is given for start event {ref!r}, but process "
                         f"{parent.get('id')!r} has {len(starts)} start events: each arrival "
                         "starts the process, and so a token at every one of them",
                         "keep one start event, or move the others into their own process")
    definitions = [c for c in _children(target) if local(c).endswith("EventDefinition")
                   or local(c) == "eventDefinitionRef"]
    if definitions:
        defs.ctx.warning(where, UNREAD, f"{what} is given for start event {ref!r}, which "
                         f"has its own trigger ({local(definitions[0])}): that trigger starts "
                         "the process, and the arrivals are ignored",
                         "give arrivals to a none start event")
        return None
    return parent.get("id") or None


def _positive_mean(dist: DeclaredDistribution, element: etree._Element, defs: Defs,
                   what: str) -> bool:
    """Whether the inter-arrival time is more than 0 on average: arrivals 0 apart would start
    instances without end at one instant."""
    from opspec.distributions import from_model

    if from_model(dist).mean > 0:
        return True
    defs.ctx.warning(element, UNREAD, f"{what}: the inter-arrival time is 0, which would start "
                     "instances without end at one instant; opspec does not read it",
                     "give a mean time between arrivals above 0")
    return False


def _read_qbp(info: etree._Element, root: etree._Element, defs: Defs,
              out: SimulationParameters) -> None:
    """A QBP ``processSimulationInfo``: task durations, the arrival rate and count."""
    for element in info.iter(f"{{{QBP}}}element"):
        ref = (element.get("elementId") or "").strip()
        distribution = element.find(f"{{{QBP}}}durationDistribution")
        if distribution is None:
            continue
        if not _names_a(defs.by_id.get(ref), TIMED, element, ref, "a QBP duration", "task",
                        defs):
            continue
        dist = qbp_distribution(distribution, defs, f"QBP duration of {ref!r}")
        if dist is not None:
            out.durations.setdefault(ref, dist)
            out.duration_source.setdefault(ref, "QBP")
    arrival = info.find(f"{{{QBP}}}arrivalRateDistribution")
    if arrival is not None:
        _qbp_arrival(info, arrival, root, defs, out)
    _qbp_resources(info, defs)


def _qbp_resources(info: etree._Element, defs: Defs) -> None:
    """QBP resources and timetables are not read: said at their lines, with what they would
    change. BIMP and Prosimos make a case wait while every resource of a task is busy, and
    work only within a resource's timetable; opspec starts a task as soon as it is reached,
    around the clock. Measured with Prosimos on tests/bpmn/data/simulation/qbp_loan.bpmn
    (docs/bpmn.md): 2 clerks instead of 50 double its mean cycle time, a 09:00-17:00
    weekday timetable makes it 60 times longer."""
    resources = info.find(f"{{{QBP}}}resources")
    if resources is not None:
        pools = [f"{r.get('totalAmount') or '?'} {r.get('name') or r.get('id')!r}"
                 for r in resources.iterfind(f"{{{QBP}}}resource")]
        defs.ctx.warning(resources, UNREAD,
                         f"QBP resources ({', '.join(pools) or 'none listed'}) are not read "
                         "by opspec: each task starts as soon as it is reached, as if a "
                         "resource were always free, where BIMP and Prosimos make a case wait "
                         "while every one is busy: cycle times agree only while resources "
                         "are plentiful", "compare with BIMP or Prosimos only where resources "
                         "are plentiful; see docs/bpmn.md, Simulation parameters")
    timetables = info.find(f"{{{QBP}}}timetables")
    for table in () if timetables is None else timetables.iterfind(f"{{{QBP}}}timetable"):
        rules = list(table.iter(f"{{{QBP}}}rule"))
        if any(_always(rule) for rule in rules):
            continue                    # 24/7: what opspec does anyway
        hours = "; ".join(f"{r.get('fromWeekDay', '?')}-{r.get('toWeekDay', '?')} "
                          f"{(r.get('fromTime') or '?')[:5]}-{(r.get('toTime') or '?')[:5]}"
                          for r in rules) or "no hours"
        defs.ctx.warning(table, UNREAD,
                         f"QBP timetable {table.get('name') or table.get('id')!r} ({hours}) "
                         "is not read by opspec: its tasks run around the clock, where BIMP "
                         "and Prosimos work on a case only within the timetable, so their "
                         "cycle times are longer by the hours outside it",
                         "compare with BIMP or Prosimos with a 24/7 timetable (from 00:00 to "
                         "23:59, MONDAY to SUNDAY); see docs/bpmn.md, Simulation parameters")


def _always(rule: etree._Element) -> bool:
    """Whether a QBP timetable rule covers every hour of every day."""
    days = (rule.get("fromWeekDay") or "").upper(), (rule.get("toWeekDay") or "").upper()
    return (days == ("MONDAY", "SUNDAY") and (rule.get("fromTime") or "").startswith("00:00")
            and (rule.get("toTime") or "").startswith("23:59"))


def _qbp_arrival(info: etree._Element, arrival: etree._Element, root: etree._Element,
                 defs: Defs, out: SimulationParameters) -> None:
    what = "QBP arrival rate"
    starts = [(process, start) for process in root.iterchildren(f"{{{BPMN}}}process")
              for start in process.iterchildren(f"{{{BPMN}}}startEvent")]
    if not starts:
        defs.ctx.warning(arrival, UNREAD, f"{what}: no process of the file has a start event "
                         "at its top level to start; it is ignored",
                         "draw a none start event in the process")
        return
    if len(starts) > 1:
        defs.ctx.warning(arrival, UNREAD, f"{what}: the file has {len(starts)} start events; "
                         f"the arrivals start {starts[0][1].get('id')!r} (the first)",
                         "keep one start event")
    start_id = starts[0][1].get("id") or ""
    process = _start_process(starts[0][1], arrival, start_id, defs, what)
    if process is None:
        return
    dist = qbp_distribution(arrival, defs, what)
    if dist is None or not _positive_mean(dist, arrival, defs, what):
        return
    count: int | None = None
    raw = info.get("processInstances")
    if raw is not None:
        try:
            count = int(raw.strip())
            if count < 0:
                raise ValueError(raw)
        except ValueError:
            defs.ctx.warning(info, UNREAD, f"QBP processInstances {raw!r} is no whole number "
                             "of 0 or more; the arrivals have no end", "give a count")
            count = None
    if info.get("startDateTime"):
        defs.info(info, "qbp-start", f"QBP startDateTime {info.get('startDateTime')!r} is not "
                  "read: the first case arrives when the run starts (day 1 00:00 of the "
                  "simulated clock)", "")
    out.arrivals.setdefault(process, (dist, count, "QBP"))


def _put(out: SimulationParameters, defs: Defs, element: etree._Element, flow: str, raw: str,
         where: str) -> None:
    value = parse_probability(raw)
    if value is None:
        defs.ctx.error(element, "bad-probability",
                       f"{where} probability {raw!r} of flow {flow!r} is not a number between "
                       "0 and 1", "write a probability such as 0.25")
        return
    if flow not in defs.by_id:
        defs.ctx.warning(element, "unknown-reference",
                         f"{where} gives a probability for {flow!r}, which is no element of "
                         "this file; it is ignored", "name a sequence flow's id")
        return
    out.probabilities.setdefault(flow, value)
    out.source.setdefault(flow, where)
