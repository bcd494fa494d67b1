"""The preemptive processor model against fixed-priority response-time analysis.

For periodic workflows released together at t=0 (the critical instant) on one processor,
the worst response time of workflow i is the least fixed point of
R_i = C_i + sum over higher-priority j of ceil(R_i / T_j) * C_j (Joseph & Pandya 1986;
J. W. S. Liu, Real-Time Systems, 2000, §6.5). The simulation must reproduce it exactly, and
show the deadline miss of a set the analysis calls unschedulable.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.xpdl.loader import load_spec

NS = "http://www.wfmc.org/2008/XPDL2.1"


def task_set(tmp_path: Path, tasks: list[tuple[str, float, float, int]]) -> Path:
    """``tasks``: (name, C seconds, T seconds, priority): one workflow each, one activity
    needing C of processor time, started every T."""
    processes = "".join(
        f'<WorkflowProcess Id="{name}"><ProcessHeader/><Activities>'
        f'<Activity Id="{name}_job"><Implementation><No/></Implementation>'
        f'<ExtendedAttributes><ExtendedAttribute Name="opspec:CpuDemand" Value="{c}"/>'
        f"</ExtendedAttributes></Activity></Activities><ExtendedAttributes>"
        f'<ExtendedAttribute Name="opspec:Period" Value="{t}"/>'
        f'<ExtendedAttribute Name="opspec:Priority" Value="{p}"/>'
        "</ExtendedAttributes></WorkflowProcess>" for name, c, t, p in tasks)
    path = tmp_path / "tasks.xpdl"
    path.write_text(f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="rt">'
                    "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor>"
                    "<Created>2026</Created></PackageHeader>"
                    f"<WorkflowProcesses>{processes}</WorkflowProcesses></Package>")
    return path


def response_time_analysis(tasks: list[tuple[str, float, float, int]]) -> dict[str, float]:
    """R_i by the classic iteration; ``inf`` once R_i exceeds the period (unschedulable)."""
    out: dict[str, float] = {}
    for name, c, t, p in tasks:
        higher = [(cj, tj) for _n, cj, tj, pj in tasks if pj > p]
        r = c + sum(cj for cj, _tj in higher)
        while True:
            nxt = c + sum(math.ceil(r / tj) * cj for cj, tj in higher)
            if nxt == r or nxt > t:
                out[name] = r if nxt == r else math.inf
                break
            r = nxt
    return out


def worst_response(path: Path, horizon: float, cpus: int = 1) -> dict[str, float]:
    config = EngineConfig(processor_model="preemptive", workers=cpus, switch_cost=0.0)
    result = Simulation(load_spec(path), config, keep_trace=True).run(until=horizon)
    started: dict[int, float] = {}
    worst: dict[str, float] = {}
    for event in result.trace or ():
        if event.kind == "process.started":
            started[event.instance] = event.time
        elif event.kind == "process.completed":
            rt = event.time - started[event.instance]
            worst[event.process] = max(worst.get(event.process, 0.0), rt)
    return worst


SCHEDULABLE = [("t1", 1.0, 4.0, 3), ("t2", 2.0, 6.0, 2), ("t3", 3.0, 12.0, 1)]


def test_worst_response_times_equal_response_time_analysis(tmp_path: Path) -> None:
    expected = response_time_analysis(SCHEDULABLE)
    assert expected == {"t1": 1.0, "t2": 3.0, "t3": 10.0}          # by hand, Liu §6.5
    simulated = worst_response(task_set(tmp_path, SCHEDULABLE), horizon=120.0)
    assert simulated == pytest.approx(expected)


def test_a_set_the_analysis_calls_unschedulable_misses_in_the_simulation(
        tmp_path: Path) -> None:
    tasks = [("t1", 2.0, 4.0, 3), ("t2", 2.0, 6.0, 2), ("t3", 3.0, 12.0, 1)]   # U = 1.08
    expected = response_time_analysis(tasks)
    assert expected["t1"] == 2.0 and expected["t2"] == 4.0 and expected["t3"] == math.inf
    simulated = worst_response(task_set(tmp_path, tasks), horizon=240.0)
    assert simulated["t1"] == pytest.approx(2.0) and simulated["t2"] == pytest.approx(4.0)
    assert simulated.get("t3", math.inf) > 12.0                       # past its period


def test_without_preemption_the_pooled_model_delays_the_highest_priority(
        tmp_path: Path) -> None:
    """The contrast that makes the preemptive model worth having: non-preemptive workers
    let a long low-priority job block the high-priority one (priority inversion by
    blocking), so t1's worst response exceeds its analysis value of 1 s."""
    tasks = [("t1", 1.0, 4.0, 3), ("t3", 3.0, 12.0, 1)]
    path = task_set(tmp_path, tasks)
    config = EngineConfig(processor_model="pooled", workers=1, switch_cost=0.0)
    result = Simulation(load_spec(path), config, keep_trace=True).run(until=48.0)
    preemptive = worst_response(path, horizon=48.0)
    assert preemptive["t1"] == pytest.approx(1.0)
    pooled: dict[str, float] = {}
    started: dict[int, float] = {}
    for event in result.trace or ():
        if event.kind == "process.started":
            started[event.instance] = event.time
        elif event.kind == "process.completed":
            pooled[event.process] = max(pooled.get(event.process, 0.0),
                                        event.time - started[event.instance])
    assert pooled["t1"] > 1.0
