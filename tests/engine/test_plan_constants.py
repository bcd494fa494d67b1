"""What src4 made constant or bound once on the from-source answer path (issue 31), held
in place: a plan tests each listener bit as a bool global set for the run's selection
(``plan_writer.by_selection``), its zero-time step counts are constants of the plan, a
constant deadline is its float, a catch's handlers are bound once, and the functions every
work item passes through make no closure cells (from source a cell is an object made and
freed at every call; see docs/engine-performance.md, "src4"). That the plans still do what
the interpreter does is held by test_plans.py, test_resume_plans.py and
test_performed_plans.py."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from opspec.engine import plans
from opspec.engine.compiled import compile_package
from opspec.engine.conditions import constant_value
from opspec.engine.offers import Offers
from opspec.engine.simulation import Simulation
from opspec.engine.triggers import Triggers
from opspec.usermodels.loader import load_user_model
from opspec.usermodels.performer import StochasticUser
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
SPECS = ("medication_dispenser.xpdl", "medication_dispenser.bpmn", "vacuum_cleaner.xpdl",
         "toy_sumo.xpdl", "medication_cart_guidance.xpdl")


def _functions(compiled: Any) -> list[Any]:
    found = []
    for proc in compiled.processes.values():
        plan = proc.plan
        if plan is not None:
            found += [plan, *plan.resumes.values(), *plan.dones.values(),
                      *plan.performs.values()]
    return found


@pytest.fixture(autouse=True)
def _plans_made(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(plans, "COMPILED", False)   # (the compiled engine makes none)


@pytest.mark.parametrize("spec", SPECS)
def test_plans_test_bool_globals_and_count_no_steps(spec: str) -> None:
    compiled = compile_package(open_spec(ROOT / "specs" / spec))
    plans.attach(compiled)
    made = _functions(compiled)
    assert made, "no plans were made"
    for fn in made:
        source = fn.__doc__
        assert "cached.bits" not in source and "bits &" not in source
        assert "steps += 1" not in source and "steps = 0" not in source
        for name in re.findall(r"\bBITS_\w+", source):
            assert re.fullmatch(r"BITS_(A|PR)\d+_(1|2|4|8|16)", name), name
        code = "\n".join(line.split("#")[0] for line in source.splitlines())
        assert not re.search(r"\bsteps\b", code)


def test_the_bits_are_bools_of_the_runs_selection() -> None:
    """After a run, every bit global of a plan is a bool, and it is the bit of the run's
    selection (a run that keeps its trace wants every event)."""
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    Simulation(compiled, keep_trace=True).run(until=86400.0)
    checked = 0
    for fn in _functions(compiled):
        space = fn.__globals__
        for name, value in space.items():
            if name.startswith("BITS_") and space.get("KEY") is not None:
                assert value is True, name
                checked += 1
    assert checked > 20


def test_a_constant_deadline_is_its_float() -> None:
    if getattr(constant_value, "__code__", None) is None:
        pytest.skip("compiled: an expression's constant is not known to the plans")
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    plans.attach(compiled)
    laters = [line.strip() for fn in _functions(compiled) for line in fn.__doc__.splitlines()
              if "state.later(" in line]
    assert laters
    for line in laters:
        delay, _fn, _ai, arg = re.fullmatch(r"state\.later\((\w+), (\S+), (\w+), (\w+)\)",
                                            line).groups()
        fn = next(f for f in _functions(compiled) if line in f.__doc__)
        value, argument = fn.__globals__[delay], fn.__globals__[arg]
        assert type(value) is float and argument == (argument[0], argument[1], value)


def test_a_catchs_handlers_are_bound_once() -> None:
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    sim = Simulation(compiled)
    triggers = sim.triggers
    assert triggers.caught_q == triggers.caught and triggers.deadline_q == triggers.deadline
    assert triggers.caught_q is triggers.caught_q


@pytest.mark.parametrize("fn", [Triggers.wait_trigger, Triggers.broadcast,
                                Offers.performer_complete, Offers._choose,
                                StochasticUser.offer, StochasticUser._finish,
                                StochasticUser._choose, StochasticUser._end_handover])
def test_the_answer_path_makes_no_closure_cells(fn: Any) -> None:
    code = getattr(fn, "__code__", None)
    if code is None:
        pytest.skip("compiled")
    assert code.co_cellvars == ()
    send = getattr(Triggers._send, "__code__", None)
    assert send is None or send.co_cellvars == ()


def test_the_user_binds_its_callbacks_once() -> None:
    """From source, with the engine's session, the user hands the same bound ``_finish``
    to every answer (no method object made per work item)."""
    model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
    import numpy as np
    user = model.performer(np.random.default_rng(1))
    assert isinstance(user, StochasticUser)
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    from opspec.engine.lanes import user_lane
    sim = Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names})
    sim.run(until=60.0)                     # (the user is attached when the run starts)
    if user._call_with is None:
        pytest.skip("compiled: the user schedules its own callback objects")
    assert user._finishing == user._finish and user._finishing is user._finishing
    assert user._ending == user._end_handover
