"""Fixed-priority response-time analysis of a package's periodic workflows.

A periodic workflow (``opspec:Period`` T) whose activities declare ``opspec:CpuDemand`` is a
task with execution time C (the sum of its activities' demands: one instance runs them all;
a demand given as a distribution counts with its upper bound — ``max`` of a uniform,
triangular or truncated normal — and one without a bound, such as an exponential, leaves the
task without a worst case: ``unbounded``, judged by the simulation alone),
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
from opspec.model.sisarl import ActivityDirectives

__all__ = ["PeriodicTask", "analyse", "demand_bound", "hyperperiod", "tasks_of"]


@dataclass(frozen=True, slots=True)
class PeriodicTask:
    """One periodic workflow as the analysis sees it; ``response`` is ``None`` when it
    exceeds the deadline (unschedulable)."""

    workflow: str
    period: float
    demand: float
    priority: int
    deadline: float
    response: float | None = None
    unbounded: bool = False          # a stochastic demand without an upper bound

    @property
    def schedulable(self) -> bool:
        return self.response is not None


def tasks_of(package: Package) -> list[PeriodicTask]:
    """The periodic workflows with a processor demand, highest priority first."""
    tasks = []
    for process in package.processes:
        directives = process.directives
        period = directives.period
        if period is None or period <= 0:
            continue
        bounds = [demand_bound(a.directives) for a in process.all_activities()]
        demand = sum(b for b in bounds if b is not None)
        unbounded = any(b is None for b in bounds)
        if demand <= 0 and not unbounded:
            continue
        priority = directives.priority if directives.priority is not None else (
            process.priority or 0)
        tasks.append(PeriodicTask(process.id, float(period), float(demand), int(priority),
                          float(directives.deadline or period), unbounded=unbounded))
    return sorted(tasks, key=lambda t: (-t.priority, t.workflow))


def demand_bound(directives: ActivityDirectives) -> float | None:
    """An activity's worst-case processor time: its CpuDemand, the upper bound of its
    distribution, or ``None`` when the distribution has none."""
    dist = directives.cpu_distribution
    if dist is None:
        return float(directives.cpu_demand or 0.0)
    if dist.kind in ("ConstantParameter", "constant"):
        return dist.get("value", dist.get("mean"))
    high = dist.get("max", dist.get("high"))
    if dist.kind in ("UniformDistribution", "uniform", "TriangularDistribution", "triangular",
                     "TruncatedNormalDistribution") and high is not None:
        return max(0.0, high)
    return None


def analyse(tasks: list[PeriodicTask]) -> list[PeriodicTask]:
    """Each task with its worst-case response time (``None`` past its deadline, or when it
    or a task of higher or equal priority has no bounded demand)."""
    out = []
    for task in tasks:
        others = [t for t in tasks if t is not task and t.priority >= task.priority]
        if task.unbounded or any(t.unbounded for t in others):
            out.append(task)
            continue
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
        out.append(PeriodicTask(task.workflow, task.period, task.demand, task.priority,
                        task.deadline, response, task.unbounded))
    return out


def hyperperiod(tasks: list[PeriodicTask], cap: float = 86_400.0) -> float:
    """The least common multiple of the periods (as exact fractions of a second), at most
    ``cap`` seconds."""
    if not tasks:
        return 0.0
    periods = [Fraction(t.period).limit_denominator(1_000_000) for t in tasks]
    lcm = Fraction(math.lcm(*(p.numerator for p in periods)),
                   math.gcd(*(p.denominator for p in periods)))
    return min(float(lcm), cap)
