"""From source, ``RunState.later`` and ``RunState.call_at_with`` make their timed entries
without calling the entry's class (no Python frame for its ``__init__``: ``_NEW``); compiled
(``TUPLES`` false) the class is called as before. Both ways the entry holds the same fields,
and a run keeps the same trace, summary and metrics (the dispenser with its user, whose
answers are ``call_at_with`` entries and whose deadlines are ``later`` entries), on the run's
own clock and on a shared SimPy environment."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import simpy

from opspec.engine import runstate
from opspec.engine.compiled import compile_package
from opspec.engine.lanes import user_lane
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation
from opspec.engine.timers import TUPLES
from opspec.usermodels.loader import load_user_model
from opspec.usermodels.performer import StochasticUser
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]

from_source = pytest.mark.skipif(not TUPLES, reason="the compiled engine calls the classes")


def _dispenser(shared: bool) -> tuple[Any, ...]:
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
    user = StochasticUser(model, user_stream(11, 0))
    sim = Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names},
                     seed=11, scope=(0,), keep_trace=True,
                     env=simpy.Environment() if shared else None)
    made: list[str] = []
    later = sim.later
    sim.later = lambda *args: (made.append("later"), later(*args))[1]  # type: ignore
    result = sim.run(until=6 * 86400.0)
    trace = [(e.time, e.kind, e.process, e.instance, e.activity, dict(e.data), e.seq)
             for e in result.trace]
    # both kinds of entry were made: the deadlines, and the user's answers (call_at_with,
    # the session's call_later_with, which the user takes from source)
    assert len(made) >= 15 and user._call_with is not None
    return trace, result.summary, result.metrics


@from_source
@pytest.mark.parametrize("shared", [False, True], ids=["own clock", "shared SimPy"])
def test_entries_made_without_their_class_run_as_the_classes_did(
        shared: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    frameless = _dispenser(shared)
    monkeypatch.setattr(runstate, "TUPLES", False)      # the classes called, as compiled
    called = _dispenser(shared)
    assert frameless == called
    trace = frameless[0]
    assert sum(1 for e in trace if e[1] == "activity.completed" and e[4] == "take_pill") >= 15


@from_source     # (compiled, the run's methods cannot be patched: the outcomes compare it)
@pytest.mark.parametrize("tuples", [True, False], ids=["frameless", "class called"])
def test_the_entry_holds_what_its_init_would_set(
        tuples: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """Frameless, the entries also go on the heap without ``schedule_timed`` (its steps in
    line): the heap, the order and the clock's wake-up are what ``schedule_timed`` leaves."""
    monkeypatch.setattr(runstate, "TUPLES", tuples)
    sim = Simulation(compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl")))
    assert sim.heaped and sim.heap == [] and sim.order == 0

    class _Ai:
        gen = 7

    def fn(*_args: Any) -> None:
        return None

    ai: Any = _Ai()
    sim.later(-1.0, fn, ai, "arg")
    sim.call_at_with(2.5, fn, "a", "b", "c")
    sim.call_at_with(1.0, fn, "d", "e", "f")
    rows = sorted(sim.heap, key=lambda row: row[1])
    assert [(at, seq) for at, seq, _entry in rows] == [(0.0, 1), (2.5, 2), (1.0, 3)]
    assert all((entry.at, entry.seq) == (at, seq) for at, seq, entry in rows)
    assert sim.order == 3 and sim.armed_at == 0.0      # armed for the earliest entry
    later, with_ = rows[0][2], rows[1][2]
    assert type(later) is runstate._Later and type(with_) is runstate._CallWith
    assert (later.state, later.fn, later.ai, later.arg, later.gen) == (sim, fn, ai, "arg", 7)
    assert (with_.state, with_.fn, with_.a, with_.b, with_.c) == (sim, fn, "a", "b", "c")
