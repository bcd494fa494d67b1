"""Gateways a diagram leaves undecided, and the branch probabilities that decide them.

An exclusive or inclusive gateway whose outgoing flows carry no condition (only labels such
as "Yes" and "No", or nothing) is a choice the diagram does not say how to make. BPMN would
take the first unconditioned flow every time: a silent default that turns a loop into a spin
at one instant and a "Yes/No" into "always Yes". opspec instead decides it as process
simulation tools do, by **branch probabilities**: a flow's ``opspec:Probability``, else the
file's BPSim scenario or QBP simulation info (:mod:`.simulation`), else uniformly at random —
and says which at the gateway's line. Every draw is a ``branch.chosen`` trace event.
"""

from __future__ import annotations

from collections.abc import Iterable

from lxml import etree

from opspec.model.process import ConditionKind, Transition
from opspec.xpdl.bpmn.common import Defs, local
from opspec.xpdl.bpmn.extensions import opspec_named
from opspec.xpdl.namespaces import OPSPEC
from opspec.xpdl.sisarl_values import parse_probability

__all__ = ["decide_undecided", "fallback_probabilities", "with_probability"]

_GATEWAYS = {"exclusiveGateway": "exclusive", "inclusiveGateway": "inclusive"}
_TOLERANCE = 1e-6


def decide_undecided(nodes: Iterable[etree._Element], transitions: list[Transition],
                     flows: dict[str, etree._Element], defs: Defs) -> list[Transition]:
    """``transitions`` with a ``probability`` on every flow out of an undecided gateway."""
    by_source: dict[str, list[Transition]] = {}
    for transition in transitions:
        by_source.setdefault(transition.source, []).append(transition)
    given: dict[str, float] = {}
    for node in nodes:
        kind = _GATEWAYS.get(local(node))
        out = by_source.get(node.get("id") or "", [])
        if kind is None or len(out) < 2:
            continue
        if any(t.condition.kind is ConditionKind.CONDITION for t in out):
            continue                  # conditions decide it (a labelled flow among them too)
        given.update(_probabilities(node, kind, out, flows, defs))
    if not given:
        return transitions
    return [with_probability(t, given[t.id]) if t.id in given else t for t in transitions]


def with_probability(transition: Transition, probability: float) -> Transition:
    return transition.with_probability(probability, _number(probability))


def fallback_probabilities(node: etree._Element, out: list[Transition], defs: Defs,
                           inputs: tuple[str, ...]) -> dict[str, float]:
    """The probabilities that decide the flows ``out`` of ``node`` while the run inputs its
    conditions read have no value (:mod:`.run_inputs`)."""
    kind = _GATEWAYS.get(local(node), "inclusive")    # conditional flows out of a task: OR
    flows = {t.id: element for t in out
             if (element := defs.by_id.get(t.id)) is not None}
    return _probabilities(node, kind, out, flows, defs, inputs)


def _probabilities(gateway: etree._Element, kind: str, out: list[Transition],
                   flows: dict[str, etree._Element], defs: Defs,
                   inputs: tuple[str, ...] = ()) -> dict[str, float]:
    declared: dict[str, float] = {}
    sources: set[str] = set()
    for transition in out:
        element = flows.get(transition.id)
        own = _own_probability(element, transition.id, defs) if element is not None else None
        if own is not None:
            declared[transition.id] = own
            sources.add("opspec:Probability")
        elif transition.id in defs.probabilities:
            declared[transition.id] = defs.probabilities[transition.id]
            sources.add(defs.probability_source.get(transition.id, "the file"))
    missing = [t.id for t in out if t.id not in declared]
    named = gateway.get('name') or gateway.get('id')
    label = (f"{kind} gateway {named!r}" if local(gateway) in _GATEWAYS
             else f"the conditional flows out of {local(gateway)} {named!r}")
    labels = [f"{t.id} ({t.name!r})" if t.name else t.id for t in out]
    result = dict(declared)
    if kind == "exclusive":
        total = sum(declared.values())
        if missing:
            if total > 1.0 + _TOLERANCE:
                defs.ctx.error(gateway, "bad-probability",
                               f"{label}: the branch probabilities given sum to "
                               f"{_number(total)}, more than 1, and flows "
                               f"{', '.join(missing)} have none",
                               "give probabilities that sum to 1 over all its flows")
                return {}
            share = max(0.0, 1.0 - total) / len(missing)
            result.update({flow: share for flow in missing})
        elif abs(total - 1.0) > _TOLERANCE:
            if total <= 0.0:
                defs.ctx.error(gateway, "bad-probability",
                               f"{label}: every branch probability is 0",
                               "give probabilities that sum to 1 over all its flows")
                return {}
            defs.ctx.warning(gateway, "probabilities-normalised",
                             f"{label}: the branch probabilities sum to {_number(total)}, not "
                             "1; opspec divides each by that sum",
                             "give probabilities that sum to 1 over all its flows")
            result = {flow: value / total for flow, value in declared.items()}
    else:
        result.update({flow: 0.5 for flow in missing})
    shares = ", ".join(f"{flow} {_percent(result[flow])}" for flow in (t.id for t in out))
    how = ("takes one flow" if kind == "exclusive" else
           "takes each flow with its probability, drawn again until at least one is taken")
    # an exclusive gateway's one flow without a probability gets what the others leave: that
    # is implied, not a default; any other missing probability is opspec's choice, said
    implied = kind == "exclusive" and len(missing) == 1 and bool(declared)
    if inputs:
        given_by = (f"the probabilities of {' and '.join(sorted(sources))}" if declared and
                    not missing else "equal probabilities" if not declared else
                    "the probabilities given and the rest shared equally")
        defs.ctx.warning(gateway, "undecided-gateway",
                         f"{label} is decided by conditions over run inputs "
                         f"({', '.join(inputs)}) that nothing in the diagram sets: in a run "
                         f"not given them, opspec decides it at random with {given_by} "
                         f"({shares}); it {how}, and each draw is a branch.chosen trace event",
                         "give the run inputs with --param NAME=VALUE, or each flow its "
                         "probability (opspec:Probability, BPSim, QBP) (docs/bpmn.md, Run "
                         "inputs)")
    elif missing and not implied:
        what = ("no condition on any flow" if not any(t.name for t in out) else
                f"only labels, no conditions, on its flows ({', '.join(labels)})")
        defs.ctx.warning(gateway, "undecided-gateway",
                         f"{label} has {what}: opspec decides it at random with "
                         + ("the probabilities given and the rest shared equally"
                            if declared else "equal probabilities")
                         + f" ({shares}); it {how}, and each draw is a branch.chosen trace "
                         "event",
                         "give each flow its probability (opspec:Probability, or a BPSim or "
                         "QBP scenario), or write conditions over data (docs/bpmn.md, "
                         "Undecided gateways)")
    else:
        defs.info(gateway, "branch-probabilities",
                  f"{label} is decided at random by the branch probabilities of "
                  f"{' and '.join(sorted(sources))} ({shares}); it {how}")
    return result


def _own_probability(flow: etree._Element, flow_id: str, defs: Defs) -> float | None:
    """A flow's ``opspec:Probability`` (extension element, or the attribute shorthand)."""
    raw: str | None = flow.get(f"{{{OPSPEC}}}Probability")
    where = flow
    for element in opspec_named(flow, "Probability"):
        raw = element.get("Value") if element.get("Value") is not None else (element.text or "")
        where = element
    if raw is None:
        return None
    value = parse_probability(raw)
    if value is None:
        defs.ctx.error(where, "bad-probability",
                       f"opspec:Probability {raw!r} of sequence flow {flow_id!r} is not a "
                       "number between 0 and 1", "write a probability such as 0.25 or 25%")
    return value


def _number(value: float) -> str:
    return f"{value:.6g}"


def _percent(value: float) -> str:
    return f"{value * 100:.4g} %"
