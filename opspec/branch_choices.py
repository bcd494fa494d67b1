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

Each refusal is a :class:`BranchRefusal`: its message is the command line's (``--branch
GATEWAY: …``) when the probabilities came from it (:func:`parse_branch_options` gives
:class:`CommandLineBranches`); a scenario file, which gives the same probabilities as a TOML
table, checks them when it is collected (:func:`read_branch_table`, :func:`check_branch_table`)
and says the refusal in its own words (``in_file``) at the key it is about (``at``); the
Python API's ``branches={...}`` is refused in its words, at its keys
(:meth:`BranchRefusal.in_api_words`).
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

__all__ = ["BranchRefusal", "Branches", "CommandLineBranches", "check_branch_table",
           "check_branches",
           "gateway_lines", "parse_branch_options", "read_branch_table", "with_branches"]

#: gateway -> flow -> probability, as the user named them
Branches = Mapping[str, Mapping[str, float]]

_SUM_TOLERANCE = 1e-9
_HINT = ("write GATEWAY=FLOW:P[,FLOW:P...], e.g. --branch \"Pill taken?=Yes:0.8,No:0.2\" "
         "(docs/bpmn.md, Undecided gateways)")
_FILE_HINT = ("name a gateway by its id or name, as opspec validate prints them (docs/bpmn.md, "
              "Undecided gateways)")
_TABLE_HINT = "write branches = { GATEWAY = { FLOW = 0.8, OTHER = 0.2 } }"


class BranchRefusal(ConfigurationError):
    """Branch probabilities refused. The message is the command line's (``--branch GATEWAY:
    …``, or the ``where`` the caller gave); ``in_file`` and ``file_hint`` say it for a file's
    ``{GATEWAY = {FLOW = P}}`` table, at ``at``: the keys, as the file names them, below that
    table (``()``: the table, ``(GATEWAY,)``, ``(GATEWAY, FLOW)``)."""

    def __init__(self, message: str, *, hint: str = "", at: tuple[str, ...] = (),
                 in_file: str = "", file_hint: str | None = None, **rest: Any) -> None:
        super().__init__(message, hint=hint, **rest)
        self.at = at
        self.in_file = in_file or message
        self.file_hint = hint if file_hint is None else file_hint

    def in_api_words(self) -> BranchRefusal:
        """The same refusal for ``opspec.run(branches={...})`` (and ``simulate``): placed at
        its keys (``branches['Pill taken?']['Yes']``), without the command line's syntax."""
        keys = "".join(f"[{key!r}]" for key in self.at)
        return BranchRefusal(f"branches{keys}: {self.in_file}",
                             hint=self.file_hint.replace("given.params", "params"),
                             at=self.at, in_file=self.in_file, file_hint=self.file_hint)


class CommandLineBranches(dict[str, dict[str, float]]):
    """Branch probabilities as ``--branch`` gave them: refused in the command line's words."""


def parse_branch_options(texts: Iterable[str]) -> CommandLineBranches:
    """The ``--branch`` texts as gateway -> flow -> probability (a later one for the same
    gateway replaces the earlier)."""
    out = CommandLineBranches()
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
    """A ``{GATEWAY = {FLOW = P}}`` table (``opspec.run(branches=...)``; a file's:
    :func:`read_branch_table`) checked, its refusals naming it ``where``."""
    if not isinstance(given, Mapping):
        raise BranchRefusal(f"{where} is not a table of gateways", hint=_TABLE_HINT,
                            in_file=f"{given!r} is not a table of gateways")
    out: dict[str, dict[str, float]] = {}
    for gateway, flows in given.items():
        if not isinstance(flows, Mapping) or not flows:
            raise BranchRefusal(f"{where}.{gateway} is not a table of flows and probabilities",
                                hint=f"write {gateway} = {{ FLOW = 0.8, OTHER = 0.2 }}",
                                at=(str(gateway),),
                                in_file=f"{flows!r} is not a table of flows and "
                                "probabilities", file_hint="write { FLOW = 0.8, OTHER = 0.2 }")
        out[str(gateway)] = {str(flow): _probability(value, f"{where}.{gateway}.{flow}",
                                                     (str(gateway), str(flow)))
                             for flow, value in flows.items()}
    return out


def read_branch_table(given: Any) -> dict[str, dict[str, float]]:
    """A file's ``branches`` table (a scenario's ``given.branches``) checked as a table of
    probabilities: a :class:`BranchRefusal` at the key it is about."""
    return check_branches(given, "branches")


def check_branch_table(package: Package, branches: Branches) -> None:
    """``branches`` (read by :func:`read_branch_table`) checked against ``package``, as a run
    given them checks them: a :class:`BranchRefusal` at the key of the gateway or flow."""
    with_branches(package, branches)


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
        what = f"{_named(gateway)} is not a gateway with a choice of flows"
        raise BranchRefusal(f"{label}: {what}", hint="name an exclusive or inclusive gateway",
                            at=(name,), in_file=what)
    if any(t.condition.kind is ConditionKind.CONDITION for t in out) or \
            any(t.probability is None for t in out):
        what = (f"the conditions of {_named(gateway)} decide it; branch probabilities apply "
                "only to a gateway the diagram leaves undecided")
        raise BranchRefusal(f"{label}: {what}",
                            hint="drop this --branch, or give the run inputs its "
                            "conditions read (--param)", at=(name,), in_file=what,
                            file_hint="leave it out of branches, or give the run inputs its "
                            "conditions read (given.params)")
    chosen = {_flow(out, flow, label, gateway, name).id: p for flow, p in given.items()}
    exclusive = gateway.split is None or gateway.split.type is GatewayType.XOR
    if exclusive:
        chosen = _exclusive(out, chosen, label, name)
    probabilities = {t.id: chosen.get(t.id, t.probability) for t in out}
    changed = {t.id: t.with_probability(probabilities[t.id]) for t in out}
    return _replace_transitions(package, process, changed)


def _exclusive(out: list[Transition], chosen: dict[str, float], label: str, name: str
               ) -> dict[str, float]:
    total = math.fsum(chosen.values())
    missing = [t.id for t in out if t.id not in chosen]
    listed = ", ".join(f"{k}:{v:g}" for k, v in chosen.items())
    written = ", ".join(f"{k} = {v:g}" for k, v in chosen.items())     # as a table says it
    if len(missing) > 1:
        what = f"flows {', '.join(missing)} have no probability"
        raise BranchRefusal(f"{label}: {what}", hint="give every flow its probability, or "
                            "leave out one: it takes the rest", at=(name,), in_file=what)
    if missing:
        if total > 1.0 + _SUM_TOLERANCE:
            raise BranchRefusal(f"{label}: {listed} sum to {total:g}, more than 1",
                                hint="an exclusive gateway's probabilities sum to 1",
                                at=(name,), in_file=f"{written} sum to {total:g}, more than 1")
        return {**chosen, missing[0]: max(0.0, 1.0 - total)}
    if abs(total - 1.0) > _SUM_TOLERANCE:
        raise BranchRefusal(f"{label}: {listed} sum to {total:g}, not 1",
                            hint="an exclusive gateway's probabilities sum to 1 "
                            "(or leave one flow out: it takes the rest)",
                            at=(name,), in_file=f"{written} sum to {total:g}, not 1")
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
        what = f"{len(found)} activities have this name"
        raise BranchRefusal(f"{where} {name}: {what}",
                            hint="name it by id: " + ", ".join(a.id for _p, a in found),
                            at=(name,), in_file=what)
    what = "no gateway of this id or name" + _closest(name, names)
    raise BranchRefusal(f"{where} {name}: {what}", hint=_HINT, at=(name,), in_file=what,
                        file_hint=_FILE_HINT)


def _flow(out: list[Transition], name: str, label: str, gateway: Activity,
          gateway_name: str) -> Transition:
    for transition in out:
        if name == transition.id:
            return transition
    named = [t for t in out if t.name == name]
    if len(named) == 1:
        return named[0]
    names = [n for t in out for n in (t.id, t.name) if n]
    close = _closest(name, names)
    raise BranchRefusal(f"{label}: no flow {name!r} out of it" + close,
                        hint="its flows are " + ", ".join(
                            f"{t.id} ({t.name!r})" if t.name else t.id for t in out),
                        at=(gateway_name, name),
                        in_file=f"no flow of this id or name out of {_named(gateway)}" + close)


def _closest(name: str, names: list[str]) -> str:
    close = difflib.get_close_matches(name, names, n=1, cutoff=0.5)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _probability(value: Any, where: str, at: tuple[str, ...] = ()) -> float:
    text = str(value).strip()
    try:
        number = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
    except ValueError:
        number = math.nan
    if isinstance(value, bool) or not 0.0 <= number <= 1.0:
        raise BranchRefusal(f"{where}: {text!r} is not a probability",
                            hint="a probability lies between 0 and 1 (0.8 or 80%)", at=at,
                            in_file=f"{text!r} is not a probability")
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
