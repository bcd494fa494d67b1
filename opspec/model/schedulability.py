"""Fixed-priority response-time analysis of a package's periodic workflows.

A periodic workflow (``opspec:Period`` T) whose activities declare ``opspec:CpuDemand`` is a
task with execution time C (the sum of its activities' demands: one instance runs them all),
priority P (``opspec:Priority``) and deadline D (``opspec:Deadline``, else T). On one
processor with preemption, its worst response time is the least fixed point of

    R = C + sum over higher-priority tasks j of ceil(R / T_j) * C_j

(Joseph & Pandya 1986; J. W. S. Liu, *Real-Time Systems*, 2000, §6.5), when R ≤ D; tasks of
equal priority count as higher (they are served in arrival order, so each may wait for the
others). ``opspec check --schedulability`` prints it beside the preemptive engine's simulation
of one hyperperiod from a synchronous release.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from opspec.model.package import Package

__all__ = ["Task", "analyse", "hyperperiod", "tasks_of"]


@dataclass(frozen=True, slots=True)
class Task:
    """One periodic workflow as the analysis sees it; ``response`` is ``None`` when it
    exceeds the deadline (unschedulable)."""

    workflow: str
    period: float
    demand: float
    priority: int
    deadline: float
    response: float | None = None

    @property
    def schedulable(self) -> bool:
        return self.response is not None


def tasks_of(package: Package) -> list[Task]:
    """The periodic workflows with a processor demand, highest priority first."""
    tasks = []
    for process in package.processes:
        directives = process.directives
        period = directives.period
        if period is None or period <= 0:
            continue
        demand = sum(a.directives.cpu_demand or 0.0 for a in process.all_activities())
        if demand <= 0:
            continue
        priority = directives.priority if directives.priority is not None else (
            process.priority or 0)
        tasks.append(Task(process.id, float(period), float(demand), int(priority),
                          float(directives.deadline or period)))
    return sorted(tasks, key=lambda t: (-t.priority, t.workflow))


def analyse(tasks: list[Task]) -> list[Task]:
    """Each task with its worst-case response time (or ``None`` past its deadline)."""
    out = []
    for task in tasks:
        others = [t for t in tasks if t is not task and t.priority >= task.priority]
        response: float | None = task.demand + sum(t.demand for t in others)
        while response is not None:
            nxt = task.demand + sum(math.ceil(response / t.period - 1e-9) * t.demand
                                    for t in others)
            if nxt > task.deadline + 1e-9:
                response = None
            elif abs(nxt - response) < 1e-12:
                break
            else:
                response = nxt
        out.append(Task(task.workflow, task.period, task.demand, task.priority,
                        task.deadline, response))
    return out


def hyperperiod(tasks: list[Task], cap: float = 86_400.0) -> float:
    """The least common multiple of the periods (as exact fractions of a second), at most
    ``cap`` seconds."""
    if not tasks:
        return 0.0
    periods = [Fraction(t.period).limit_denominator(1_000_000) for t in tasks]
    lcm = Fraction(math.lcm(*(p.numerator for p in periods)),
                   math.gcd(*(p.denominator for p in periods)))
    return min(float(lcm), cap)
