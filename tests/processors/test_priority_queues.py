"""The priority-queues processor model: the source's Windows CE engine (EMWF TR-IIS-08-005
§4.2.2) — a FIFO queue per priority with its own worker thread(s), a leader thread above them
that queues work and handles completions in priority order, on K processors with fixed-priority
preemption and a cost per context switch (docs/processor-models.md).

The expected times below are worked out by hand from that definition, event by event, in the
comments; with no switch cost and one activity per workflow the model must also agree with
fixed-priority response-time analysis (Joseph & Pandya 1986; Liu 2000, §6.5), like the
preemptive model.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from test_preemptive import SCHEDULABLE, response_time_analysis, task_set

from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.xpdl.loader import load_spec

NS = "http://www.wfmc.org/2008/XPDL2.1"
MS = 0.001


def workflows(tmp_path: Path, flows: list[tuple[str, int, float, list[tuple[float, int]]]]
              ) -> Path:
    """``flows``: (name, priority, period s, [(CPU demand s, priority increment), ...]): a
    workflow of general activities in sequence, started every period from t = 0."""
    parts = []
    for name, priority, period, steps in flows:
        acts = "".join(
            f'<Activity Id="{name}{i}"><Implementation><No/></Implementation>'
            f'<ExtendedAttributes><ExtendedAttribute Name="opspec:CpuDemand" Value="{c}"/>'
            f'<ExtendedAttribute Name="opspec:PriorityIncrement" Value="{inc}"/>'
            "</ExtendedAttributes></Activity>" for i, (c, inc) in enumerate(steps, 1))
        trans = "".join(f'<Transition Id="{name}t{i}" From="{name}{i}" To="{name}{i + 1}"/>'
                        for i in range(1, len(steps)))
        parts.append(
            f'<WorkflowProcess Id="{name}"><ProcessHeader/><Activities>{acts}</Activities>'
            f"<Transitions>{trans}</Transitions><ExtendedAttributes>"
            f'<ExtendedAttribute Name="opspec:Period" Value="{period}"/>'
            f'<ExtendedAttribute Name="opspec:Priority" Value="{priority}"/>'
            "</ExtendedAttributes></WorkflowProcess>")
    path = tmp_path / "flows.xpdl"
    path.write_text(f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="ce">'
                    "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor>"
                    "<Created>2026</Created></PackageHeader>"
                    f"<WorkflowProcesses>{''.join(parts)}</WorkflowProcesses></Package>",
                    encoding="utf-8")
    return path


def responses(path: Path, until: float, **config: object
              ) -> tuple[dict[str, list[float]], dict[str, object]]:
    """Every instance's response time (completion - start), per workflow, and the summary."""
    options = {"processor_model": "priority-queues", "workers": 1, **config}
    result = Simulation(load_spec(path), EngineConfig(**options),  # type: ignore[arg-type]
                        keep_trace=True).run(until=until)
    started: dict[int, float] = {}
    out: dict[str, list[float]] = {}
    for event in result.trace or ():
        if event.kind == "process.started":
            started[event.instance] = event.time
        elif event.kind == "process.completed":
            out.setdefault(event.process, []).append(event.time - started[event.instance])
    return out, result.summary


@pytest.mark.parametrize("low_ms", [50, 500])
def test_a_long_low_priority_item_delays_high_priority_work_only_by_switches(
        tmp_path: Path, low_ms: float) -> None:
    """One processor, switch cost s = 1 ms; H: 10 ms every 100 ms at priority 5; L: one long
    item at priority 1. By the model, H's worker preempts L's, so every H instance takes
    s (leader, woken by the timer: it may preempt L) + s (into H's worker) + 10 ms + s (back
    to the leader, which ends H's workflow) = 13 ms, however long L is.

    L = 500 ms, by hand: leader 0-1, H 1-12, leader 12-13 (H done at 13), L's switch 13-14,
    L runs 14-100 (86 ms); each later H release takes 100-114 (leader, H, leader, L's resume
    switch), so L runs 86 ms per 100 ms: 430 ms by t = 500, the last 70 ms in 514-584, then
    the leader 584-585: L's response is 585 ms = 500 + 7 switches of its own + 6 H instances
    of 13 ms. L = 50 ms: 13 + 1 + 50 + 1 = 65 ms."""
    path = workflows(tmp_path, [("H", 5, 0.1, [(10 * MS, 0)]),
                                ("L", 1, 1.0, [(low_ms * MS, 0)])])
    got, summary = responses(path, until=0.95, switch_cost=MS)
    assert got["H"] == pytest.approx([13 * MS] * 10)
    assert got["L"] == pytest.approx([(585 if low_ms == 500 else 65) * MS])
    assert summary["pool"]["preemptions"] == (5 if low_ms == 500 else 0)

    # the contrast: the pooled model's one non-preemptive worker makes H wait for L (L runs
    # 11-512 ms, so the H released at 100 ms ends at 523: 423 ms)
    pooled, _ = responses(path, until=0.95, processor_model="pooled", switch_cost=MS)
    assert max(pooled["H"]) == pytest.approx((423 if low_ms == 500 else 11) * MS)


def test_the_leader_handles_completions_in_priority_order(tmp_path: Path) -> None:
    """Two processors, s = 1 ms, one worker per queue. X (priority 1) runs x1 (9.5 ms), then x2
    at priority 1+1 = 2; Y (priority 3) runs y1 (10 ms), then y2 at 3-1 = 2; x2 and y2 take
    10 ms and share queue 2 and its one worker.

    By hand: leader 0-1 queues both; x1 and y1 switch in 1-2 on the two processors; x1 ends at
    11.5, the leader switches in 11.5-12.5; y1 ends at 12, during that switch. At 12.5 the
    leader finds both completed and, as the design says, handles the higher priority first:
    y2 enters queue 2 before x2. y2: 12.5-13.5-23.5; the leader 23.5-24.5 ends Y at 24.5;
    meanwhile queue 2's worker took x2 (23.5-24.5-34.5) and the leader ends X at 35.5.
    Handled in the order they completed (x1 first), X would end at 24.5 and Y at 35.5."""
    path = workflows(tmp_path, [("X", 1, 1.0, [(9.5 * MS, 0), (10 * MS, 1)]),
                                ("Y", 3, 1.0, [(10 * MS, 0), (10 * MS, -1)])])
    got, _ = responses(path, until=0.5, workers=2, switch_cost=MS)
    assert got["Y"] == pytest.approx([24.5 * MS])
    assert got["X"] == pytest.approx([35.5 * MS])

    # a second worker per queue runs x2 beside y2 (both queued at 12.5): both end at 24.5
    both, _ = responses(path, until=0.5, workers=2, switch_cost=MS, queue_workers=2)
    assert both["X"] == pytest.approx([24.5 * MS]) and both["Y"] == pytest.approx([24.5 * MS])


def test_context_switch_costs_add_up_as_computed_by_hand(tmp_path: Path) -> None:
    """One processor, s = 1 ms. A (priority 2): a1 10 ms then a2 5 ms; B (priority 1): b1
    20 ms; both start at 0. By hand: leader 0-1 (queues a1, b1), a1 1-2-12, leader 12-13
    (queues a2), a2 13-14-19, leader 19-20 (A ends), b1 20-21-41, leader 41-42 (B ends).
    A: 15 ms of work + 5 switches = 20 ms; B: 35 ms + 7 = 42 ms; 7 context switches, 4 of
    them into the leader; the processor busy for 42 ms."""
    path = workflows(tmp_path, [("A", 2, 1.0, [(10 * MS, 0), (5 * MS, 0)]),
                                ("B", 1, 1.0, [(20 * MS, 0)])])
    got, summary = responses(path, until=0.5, switch_cost=MS)
    assert got == {"A": pytest.approx([20 * MS]), "B": pytest.approx([42 * MS])}
    pool = summary["pool"]
    assert pool["switches"] == 7 and pool["leader_passes"] == 4
    assert pool["busy_time"] == pytest.approx(42 * MS)
    free, _ = responses(path, until=0.5, switch_cost=0.0)
    assert free == {"A": pytest.approx([15 * MS]), "B": pytest.approx([35 * MS])}


def test_without_switch_cost_it_agrees_with_response_time_analysis(tmp_path: Path) -> None:
    """One worker per priority, preemptive on one processor, free switches: for periodic
    single-activity workflows released together the worst responses are the analysis's."""
    expected = response_time_analysis(SCHEDULABLE)
    got, _ = responses(task_set(tmp_path, SCHEDULABLE), until=120.0, switch_cost=0.0)
    assert {name: max(values) for name, values in got.items()} == pytest.approx(expected)


def test_one_worker_per_queue_serialises_a_level_even_with_a_free_processor(
        tmp_path: Path) -> None:
    """Two workflows of the same priority, 10 ms each, on two processors with no switch
    cost: one worker serves their queue, so the second waits for the first (10 ms, then
    20 ms); two workers per queue run them together."""
    path = workflows(tmp_path, [("P", 2, 1.0, [(10 * MS, 0)]), ("Q", 2, 1.0, [(10 * MS, 0)])])
    one, _ = responses(path, until=0.5, workers=2, switch_cost=0.0)
    assert sorted(one["P"] + one["Q"]) == pytest.approx([10 * MS, 20 * MS])
    two, _ = responses(path, until=0.5, workers=2, switch_cost=0.0, queue_workers=2)
    assert sorted(two["P"] + two["Q"]) == pytest.approx([10 * MS, 10 * MS])
