"""The ready queue of zero-time work over long bursts (issue 31's Python-protocol pass).

``RunState.drain`` reads the queue, a list, from the front and drops what it has run every
4,096 items (``_COMPACT``), so a burst of thousands of tokens at one instant neither grows the
list without end nor loses, repeats or reorders a token. The rule the order checks is WCP-2
(Parallel Split) of the workflow patterns (Russell et al. 2006): "the divergence of a branch
into two or more parallel branches each of which execute concurrently" -- each branch runs
once -- and WCP-3 (Synchronization): "the convergence of two or more branches into a single
subsequent branch such that the thread of control is passed to the subsequent branch when all
input branches have been enabled" -- the merge runs once, after every branch. Among
activities at one instant the engine keeps the order the tokens were queued in: the split's
declared order.
"""

from __future__ import annotations

from builders import act, pkg, proc
from engine_runs import completed, events, run

from opspec.model import Package

#: enough branches for one drain to run well over 4,096 items (two per branch)
BRANCHES = 2_600


def _wide_split_and_merge() -> Package:
    names = [f"b{i}" for i in range(BRANCHES)]
    acts = [act("s", split="AND"), *names, act("m", join="AND"), "e"]
    trans = [("s", n) for n in names] + [(n, "m") for n in names] + [("m", "e")]
    return pkg(proc("p", acts, trans))


def test_thousands_of_tokens_at_one_instant_each_run_once_in_the_order_queued() -> None:
    result = run(_wide_split_and_merge())
    done = completed(result)
    branches = [a for a in done if a.startswith("b")]
    assert branches == [f"b{i}" for i in range(BRANCHES)]
    assert done.count("m") == 1 and done.count("e") == 1
    assert done.index("m") > done.index(f"b{BRANCHES - 1}")
    assert result.summary["instances"] == {"started": 1, "completed": 1, "terminated": 0,
                                           "aborted": 0, "open": 0}
    assert all(e.time == 0.0 for e in events(result, "activity.completed"))


def test_the_queue_is_empty_once_the_burst_is_drained() -> None:
    from opspec.engine.compiled import compile_package
    from opspec.engine.simulation import Simulation

    sim = Simulation(compile_package(_wide_split_and_merge()))
    sim.start("p")          # (booting runs the instance the package starts by itself too)
    assert sim.ready == []
    assert sim.counts["completed"] == sim.counts["started"] >= 1
