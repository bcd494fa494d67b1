"""Simulation parameters as process-simulation tools write them into a BPMN file.

A diagram drawn for people often leaves a choice undecided: an exclusive gateway whose flows
carry only labels ("Yes", "No"). Simulation tools answer "which branch, how often" with
**branch probabilities** attached to the diagram, in one of two common forms, both read here:

- BPSim (WfMC, versions 1.0 and 2.0): ``bpsim:BPSimData/bpsim:Scenario/bpsim:ElementParameters
  [@elementRef=FLOW]/bpsim:ControlParameters/bpsim:Probability/bpsim:FloatingParameter/@value``,
  inside a ``bpmn:relationship`` (or any ``bpmn:extensionElements``) of the definitions. The
  first scenario is the one read (BPSim's own default when a tool asks for none).
- QBP, the format of BIMP and Apromore's simulator: ``qbp:processSimulationInfo/
  qbp:sequenceFlows/qbp:sequenceFlow[@elementId=FLOW]/@executionProbability``.

A flow's own ``opspec:Probability`` directive (read by the process builder) wins over both.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Final

from lxml import etree

from opspec.xpdl.bpmn.common import Defs, local, namespace
from opspec.xpdl.sisarl_values import parse_probability

__all__ = ["BPSIM_NAMESPACES", "QBP", "SimulationParameters", "read_simulation_parameters"]

BPSIM_NAMESPACES: Final = frozenset({"http://www.bpsim.org/schemas/1.0",
                                     "http://www.bpsim.org/schemas/2.0"})
QBP: Final = "http://www.qbp-simulator.com/Schema201212"


@dataclass(frozen=True, slots=True)
class SimulationParameters:
    """Branch probabilities by sequence-flow id, and where each was read (for messages)."""

    probabilities: dict[str, float] = field(default_factory=dict)
    source: dict[str, str] = field(default_factory=dict)


def read_simulation_parameters(root: etree._Element, defs: Defs) -> SimulationParameters:
    """The branch probabilities a BPSim scenario or a QBP simulation info gives."""
    out = SimulationParameters()
    scenario = _first_bpsim_scenario(root)
    if scenario is not None:
        for parameters in scenario:
            if not isinstance(parameters.tag, str) or local(parameters) != "ElementParameters":
                continue
            flow = (parameters.get("elementRef") or "").strip()
            for probability in parameters.iter():
                if not isinstance(probability.tag, str) or local(probability) != "Probability":
                    continue
                for value_element in probability:
                    if isinstance(value_element.tag, str) and value_element.get("value"):
                        _put(out, defs, value_element, flow, value_element.get("value") or "",
                             "BPSim")
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
