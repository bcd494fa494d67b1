"""Variables a diagram's conditions read that nothing in the diagram sets: run inputs.

A modeller's diagram is drawn for an application that sets process variables at run time
(Camunda's ``${score > 50}``, ``${skipParallel}``). Refusing such a file would refuse most
real diagrams; inventing a value would run something the diagram does not say. opspec makes
each such variable a **run input**: a package data field without a value (marked
``opspec:RunInput``), which a run is given with ``--param NAME=VALUE``, a distribution
(``--param NAME~DIST``) or a data file (``--params FILE``: :mod:`opspec.commands._params`),
``params=`` in Python, ``params`` in a scenario's ``given``. Until one is given, the gateways whose conditions read it are
decided at random by branch probabilities (:mod:`.branches`): said at the condition's line,
never silent.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

from opspec.model.checks_support import names_read
from opspec.model.common import ExtendedAttribute
from opspec.model.data import BasicKind, BasicType, DataField
from opspec.model.expressions import Binary, Expression, Literal, Name, Unary
from opspec.model.process import ConditionKind, Transition, WorkflowProcess
from opspec.xpdl.bpmn.branches import fallback_probabilities, with_probability
from opspec.xpdl.bpmn.common import Defs, literal_kind

__all__ = ["RUN_INPUT", "with_run_inputs"]

#: The extended attribute that marks a package data field as a run input.
RUN_INPUT = "opspec:RunInput"


def with_run_inputs(processes: list[WorkflowProcess], package_fields: Iterable[DataField],
                    defs: Defs) -> tuple[list[WorkflowProcess], tuple[DataField, ...]]:
    """The processes (with fallback probabilities on the flows whose conditions read a run
    input) and the run inputs, as package data fields."""
    package_ids = {f.id for f in package_fields}
    inputs: dict[str, DataField] = {}
    out: list[WorkflowProcess] = []
    for process in processes:
        declared = {f.id for f in (*process.data_fields, *process.formal_parameters)}
        declared |= package_ids
        sets = {a.target.split(".", 1)[0] for activity in process.all_activities()
                for a in activity.assignments}
        sets |= {a.target.split(".", 1)[0] for t in _transitions(process) for a in t.assignments}
        reading: dict[str, list[str]] = {}           # flow source -> run inputs read
        for transition in _transitions(process):
            condition = transition.condition
            if condition.kind is not ConditionKind.CONDITION:
                continue
            for name in names_read(condition.expression):
                if name in declared or name in sets:
                    continue
                reading.setdefault(transition.source, []).append(name)
                if name not in inputs:
                    inputs[name] = _run_input(name, condition.expression, transition)
                    _say(defs, name, transition, process)
        if reading:
            process = _with_fallbacks(process, reading, defs)
        out.append(process)
    return out, tuple(inputs.values())


def _transitions(process: WorkflowProcess) -> list[Transition]:
    found = list(process.transitions)
    for activity_set in process.activity_sets:
        found.extend(activity_set.transitions)
    return found


def _run_input(name: str, expression: Expression | None, transition: Transition) -> DataField:
    return DataField(id=name, type=BasicType(kind=_kind_of(name, expression)),
                     location=transition.location,
                     extended_attributes=(ExtendedAttribute(name=RUN_INPUT, value="true"),))


def _kind_of(name: str, expression: Expression | None) -> BasicKind:
    """The type a condition gives ``name``: that of a literal it is compared with, boolean
    when it is tested on its own (``${skipParallel}``, ``not skip``), else a string."""
    stack: list[Expression] = [expression] if expression is not None else []
    while stack:
        node = stack.pop()
        if isinstance(node, Binary):
            for mine, other in ((node.left, node.right), (node.right, node.left)):
                if isinstance(mine, Name) and mine.path[0] == name and isinstance(other, Literal):
                    return literal_kind(other)
            stack.extend((node.left, node.right))
        elif isinstance(node, Unary):
            stack.append(node.operand)
    if isinstance(expression, Name) or (isinstance(expression, Unary)
                                        and isinstance(expression.operand, Name)):
        return BasicKind.BOOLEAN
    return BasicKind.STRING


def _say(defs: Defs, name: str, transition: Transition, process: WorkflowProcess) -> None:
    where = defs.by_id.get(transition.id)
    defs.ctx.warning(where, "run-input",
                     f"the condition of sequence flow {transition.id!r} reads {name!r}, which "
                     f"nothing in process {process.id!r} sets (the application would set it at "
                     f"run time): it is a run input; until a run is given a value, the choice "
                     f"it decides is drawn at random (the shares are said at the gateway)",
                     f"give it with --param {name}=VALUE, a distribution (--param "
                     f"'{name}~uniform(0, 100)'), or a data file (--params FILE.csv: one row "
                     f"per simulated user) to run and evaluate; params={{'{name}': ...}} from "
                     "Python or given = { params = {...} } in a scenario; or declare it "
                     "(docs/bpmn.md, Run inputs)")


def _with_fallbacks(process: WorkflowProcess, reading: dict[str, list[str]], defs: Defs
                    ) -> WorkflowProcess:
    """Every flow out of a node whose conditions read a run input gets the probability that
    decides it while the run input has no value."""
    shares: dict[str, float] = {}
    for source, names in reading.items():
        flows = [t for t in _transitions(process) if t.source == source]
        node = defs.by_id.get(source)
        if node is None or len(flows) < 2:
            continue
        shares.update(fallback_probabilities(node, flows, defs, tuple(dict.fromkeys(names))))
    if not shares:
        return process

    def fix(transitions: tuple[Transition, ...]) -> tuple[Transition, ...]:
        return tuple(with_probability(t, shares[t.id]) if t.id in shares else t
                     for t in transitions)

    return dataclasses.replace(
        process, transitions=fix(process.transitions),
        activity_sets=tuple(dataclasses.replace(s, transitions=fix(s.transitions))
                            for s in process.activity_sets))

