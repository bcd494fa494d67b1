"""Branch probabilities given at run time (``--branch``, a scenario's ``given.branches``).

A gateway the diagram leaves undecided (no condition opspec can evaluate) is drawn with branch
probabilities read from the file (docs/bpmn.md, Undecided gateways). A run can give them
instead, per gateway: ``--branch "Pill taken?=Yes:0.8,No:0.2"``. The given probabilities
replace the file's for that gateway in the package *before* it is compiled, so every door
(``opspec run``/``evaluate`` and its workers, ``opspec.run``, scenarios) runs the same spec and
one seed draws the same branches whatever the number of workers.

Rules (said in each refusal): the gateway and its flows are named by id or by name, as
``opspec validate`` prints them; a probability lies in [0, 1] (``0.8`` or ``80%``); an
exclusive gateway's probabilities sum to 1 within 1e-9, or exactly one of its flows is left out
and takes the rest; an inclusive gateway's are each flow's own chance (flows left out keep the
file's). A gateway whose conditions decide it is refused: there is nothing to draw.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from collections.abc import Iterable, Mapping
from typing import Any

from opspec.errors import ConfigurationError
from opspec.model import Package
from opspec.model.activities import Activity, GatewayType
from opspec.model.process import ConditionKind, Transition

__all__ = ["Branches", "check_branches", "gateway_lines", "parse_branch_options",
           "with_branches"]

#: gateway -> flow -> probability, as the user named them
Branches = Mapping[str, Mapping[str, float]]

_SUM_TOLERANCE = 1e-9
_HINT = ("write GATEWAY=FLOW:P[,FLOW:P...], e.g. --branch \"Pill taken?=Yes:0.8,No:0.2\" "
         "(docs/bpmn.md, Undecided gateways)")


def parse_branch_options(texts: Iterable[str]) -> dict[str, dict[str, float]]:
    """The ``--branch`` texts as gateway -> flow -> probability (a later one for the same
    gateway replaces the earlier)."""
    out: dict[str, dict[str, float]] = {}
    for text in texts:
        gateway, sep, rest = text.partition("=")
        if not sep or not gateway.strip() or not rest.strip():
            raise ConfigurationError(f"--branch {text!r} is not GATEWAY=FLOW:P[,FLOW:P...]",
                                     hint=_HINT)
        flows: dict[str, float] = {}
        for part in rest.split(","):
            flow, colon, value = part.rpartition(":")
            if not colon or not flow.strip():
                raise ConfigurationError(f"--branch {text!r}: {part.strip()!r} is not FLOW:P",
                                         hint=_HINT)
            flows[flow.strip()] = _probability(value, f"--branch {text!r}")
        out[gateway.strip()] = flows
    return out


def check_branches(given: Any, where: str) -> dict[str, dict[str, float]]:
    """A ``{GATEWAY = {FLOW = P}}`` table (a scenario's ``given.branches``) checked."""
    if not isinstance(given, Mapping):
        raise ConfigurationError(f"{where} is not a table of gateways",
                                 hint="write branches = { GATEWAY = { FLOW = 0.8, OTHER = 0.2 } }")
    out: dict[str, dict[str, float]] = {}
    for gateway, flows in given.items():
        if not isinstance(flows, Mapping) or not flows:
            raise ConfigurationError(f"{where}.{gateway} is not a table of flows and "
                                     "probabilities",
                                     hint=f"write {gateway} = {{ FLOW = 0.8, OTHER = 0.2 }}")
        out[str(gateway)] = {str(flow): _probability(value, f"{where}.{gateway}.{flow}")
                             for flow, value in flows.items()}
    return out


def with_branches(package: Package, branches: Branches, where: str = "--branch") -> Package:
    """``package`` with the run-time ``branches`` replacing the file's probabilities of the
    gateways they name; anything they cannot apply to is a ConfigurationError."""
    for gateway_name, flows in check_branches(branches, where).items():
        package = _apply(package, gateway_name, flows, where)
    return package


def gateway_lines(package: Package, branches: Branches, where: str = "--branch"
                  ) -> frozenset[int]:
    """The source lines of the gateways ``branches`` name (their file's ``undecided-gateway``
    warning, about the probabilities the run no longer uses, is dropped)."""
    lines = set()
    for name in branches:
        location = _gateway(package, name, where)[1].location
        if location is not None and location.line is not None:
            lines.add(location.line)
    return frozenset(lines)


def _apply(package: Package, name: str, given: Mapping[str, float], where: str) -> Package:
    process, gateway = _gateway(package, name, where)
    out = [t for t in _transitions(process) if t.source == gateway.id]
    label = f"{where} {name}"
    if not gateway.is_route or len(out) < 2:
        raise ConfigurationError(f"{label}: {_named(gateway)} is not a gateway with a choice "
                                 "of flows", hint="name an exclusive or inclusive gateway")
    if any(t.condition.kind is ConditionKind.CONDITION for t in out) or \
            any(t.probability is None for t in out):
        raise ConfigurationError(f"{label}: the conditions of {_named(gateway)} decide it; "
                                 "branch probabilities apply only to a gateway the diagram "
                                 "leaves undecided",
                                 hint="drop this --branch, or give the run inputs its "
                                 "conditions read (--param)")
    chosen = {_flow(out, flow, label).id: p for flow, p in given.items()}
    exclusive = gateway.split is None or gateway.split.type is GatewayType.XOR
    if exclusive:
        chosen = _exclusive(out, chosen, label)
    probabilities = {t.id: chosen.get(t.id, t.probability) for t in out}
    changed = {t.id: t.with_probability(probabilities[t.id]) for t in out}
    return _replace_transitions(package, process, changed)


def _exclusive(out: list[Transition], chosen: dict[str, float], label: str
               ) -> dict[str, float]:
    total = math.fsum(chosen.values())
    missing = [t.id for t in out if t.id not in chosen]
    listed = ", ".join(f"{k}:{v:g}" for k, v in chosen.items())
    if len(missing) > 1:
        raise ConfigurationError(f"{label}: flows {', '.join(missing)} have no probability",
                                 hint="give every flow its probability, or leave out one: "
                                 "it takes the rest")
    if missing:
        if total > 1.0 + _SUM_TOLERANCE:
            raise ConfigurationError(f"{label}: {listed} sum to {total:g}, more than 1",
                                     hint="an exclusive gateway's probabilities sum to 1")
        return {**chosen, missing[0]: max(0.0, 1.0 - total)}
    if abs(total - 1.0) > _SUM_TOLERANCE:
        raise ConfigurationError(f"{label}: {listed} sum to {total:g}, not 1",
                                 hint="an exclusive gateway's probabilities sum to 1 "
                                 "(or leave one flow out: it takes the rest)")
    return chosen


def _gateway(package: Package, name: str, where: str) -> tuple[Any, Activity]:
    found: list[tuple[Any, Activity]] = []
    names: list[str] = []
    for process in package.processes:
        for activity in process.all_activities():
            if activity.is_route:
                names.extend(n for n in (activity.id, activity.name) if n)
            if activity.id == name:
                return process, activity
            if activity.name == name:
                found.append((process, activity))
    if len(found) == 1:
        return found[0]
    if found:
        raise ConfigurationError(f"{where} {name}: {len(found)} activities have this name",
                                 hint="name it by id: "
                                 + ", ".join(a.id for _p, a in found))
    raise ConfigurationError(f"{where} {name}: no gateway of this id or name"
                             + _closest(name, names), hint=_HINT)


def _flow(out: list[Transition], name: str, label: str) -> Transition:
    for transition in out:
        if name == transition.id:
            return transition
    named = [t for t in out if t.name == name]
    if len(named) == 1:
        return named[0]
    names = [n for t in out for n in (t.id, t.name) if n]
    raise ConfigurationError(f"{label}: no flow {name!r} out of it" + _closest(name, names),
                             hint="its flows are " + ", ".join(
                                 f"{t.id} ({t.name!r})" if t.name else t.id for t in out))


def _closest(name: str, names: list[str]) -> str:
    close = difflib.get_close_matches(name, names, n=1, cutoff=0.5)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _probability(value: Any, where: str) -> float:
    text = str(value).strip()
    try:
        number = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
    except ValueError:
        number = math.nan
    if isinstance(value, bool) or not 0.0 <= number <= 1.0:
        raise ConfigurationError(f"{where}: {text!r} is not a probability",
                                 hint="a probability lies between 0 and 1 (0.8 or 80%)")
    return number


def _named(activity: Activity) -> str:
    return f"{activity.id} ({activity.name!r})" if activity.name else activity.id


def _transitions(process: Any) -> list[Transition]:
    return [*process.transitions,
            *(t for s in process.activity_sets for t in s.transitions)]


def _replace_transitions(package: Package, process: Any, changed: Mapping[str, Transition]
                         ) -> Package:
    def swap(transitions: tuple[Transition, ...]) -> tuple[Transition, ...]:
        return tuple(changed.get(t.id, t) if t.source in {c.source for c in changed.values()}
                     else t for t in transitions)

    sets = tuple(dataclasses.replace(s, transitions=swap(s.transitions))
                 for s in process.activity_sets)
    new = dataclasses.replace(process, transitions=swap(process.transitions),
                              activity_sets=sets)
    return dataclasses.replace(package, processes=tuple(
        new if p is process else p for p in package.processes))
