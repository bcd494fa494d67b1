"""Never a silent hang: every shape of a run whose simulated clock stops advancing ends within
seconds with a ZeroTimeCycleError naming the process, the activities of the cycle and the
simulated time (the specs are in ``hang_specs/``; see docs/soundness.md)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import pytest
from builders import act, manual, pkg, proc

import opspec
from opspec.engine.simulation import Simulation
from opspec.engine.zero_time import MAX_INSTANT_STEPS, max_instant_steps
from opspec.errors import ExecutionError, ZeroTimeCycleError
from opspec.model import DeclaredDistribution as Distribution
from opspec.xpdl.loader import load_spec

SPECS = Path(__file__).parent / "hang_specs"
#: spec -> (process named, activities of the cycle)
HANGS = {
    "cycle": ("spin", ["B", "C"]),
    "self_start": ("again", ["restart"]),
    "loop": ("looping", ["spin"]),
    "zero_timer": ("ticking", ["A", "wait"]),
}


@pytest.fixture
def small_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "20000")


def named(message: str, process: str) -> list[str]:
    """The activities the message names for ``process``."""
    part = message.split(f"process {process!r} (")[1]
    return part.split("): ")[1].split(" (")[0].split("; ")[0].split(", ")


@pytest.mark.usefixtures("small_limit")
@pytest.mark.parametrize("name", list(HANGS))
def test_each_hang_shape_stops_with_the_process_the_cycle_and_the_time(name: str) -> None:
    process, cycle = HANGS[name]
    sim = Simulation(load_spec(SPECS / f"{name}.xpdl"))
    with pytest.raises(ZeroTimeCycleError) as caught:
        sim.run(until=3600)
    message = str(caught.value)
    assert "\n" not in message
    # placed at the cycle: the line of the first activity it names
    path = SPECS / f"{name}.xpdl"
    first = cycle[0]
    line = next(n for n, text in enumerate(path.read_text().splitlines(), 1)
                if f'<Activity Id="{first}"' in text)
    assert message.startswith(f"{path}:{line}: the simulated clock stopped advancing at "
                              "t=0.000 s (d1 00:00:00)")
    assert named(message, process) == cycle
    assert "OPSPEC_MAX_INSTANT_STEPS" in message
    assert caught.value.sim_time == 0.0
    assert isinstance(caught.value, ExecutionError)


def test_the_default_limit_ends_a_hang_within_seconds() -> None:
    assert max_instant_steps() == MAX_INSTANT_STEPS
    began = time.perf_counter()
    with pytest.raises(ZeroTimeCycleError, match="process 'spin' \\(instance 1\\): B, C"):
        Simulation(load_spec(SPECS / "cycle.xpdl")).run()
    assert time.perf_counter() - began < 20       # about one second from source


@pytest.mark.usefixtures("small_limit")
def test_a_cycle_that_starts_later_names_that_time() -> None:
    # A takes an hour, then B -> C -> B forever at t = 3600
    package = pkg(proc("p", [act("A", duration=lasts(3600.0)),
                             act("B", join="XOR"), act("C", split="XOR"), "D"],
                       [("A", "B"), ("B", "C"), ("C", "B", "1 == 1"), ("C", "D", "otherwise")]))
    with pytest.raises(ZeroTimeCycleError) as caught:
        Simulation(package).run(until=86_400)
    assert "at t=3600.000 s (d1 01:00:00)" in str(caught.value)
    assert caught.value.sim_time == 3600.0


@pytest.mark.usefixtures("small_limit")
def test_a_performer_that_calls_back_with_no_delay_forever_is_caught() -> None:
    """Zero-delay SimPy events that queue no engine work (the second shape of a hang)."""

    class Busy:
        session: Any = None

        def attach(self, session: Any) -> None:
            self.session = session

        def offer(self, item: Any) -> None:
            def again() -> None:
                self.session.call_later(0.0, again)
            self.session.call_later(0.0, again)

        def withdraw(self, item: Any, reason: str) -> None:
            pass

    package = pkg(proc("p", [manual("ask")]))
    sim = Simulation(package, performers={"user": Busy()})
    with pytest.raises(ZeroTimeCycleError, match="SimPy events that move no activity"):
        sim.run(until=60)


@pytest.mark.usefixtures("small_limit")
def test_stepping_is_guarded_too() -> None:
    """What the walkthrough and wall-clock runs use."""
    package = pkg(proc("p", [act("A", duration=lasts(5.0)),
                             act("B", join="XOR"), act("C", split="XOR"), "D"],
                       [("A", "B"), ("B", "C"), ("C", "B", "1 == 1"), ("C", "D", "otherwise")]))
    sim = Simulation(package)
    with pytest.raises(ZeroTimeCycleError, match="at t=5.000 s"):
        for _ in range(100):
            sim.step()


def test_much_work_at_one_instant_below_the_limit_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """A loop counting to 300 at one instant is no hang; the count starts again whenever the
    clock moves, so 50 such bursts an hour apart run too."""
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "2000")
    package = pkg(proc("p", [
        "S", act("tick", duration=lasts(3600.0), assign=[("n", "0")],
            join="XOR"),
        act("B", join="XOR"), act("C", split="XOR", assign=[("n", "n + 1")]),
        act("D", split="XOR", assign=[("laps", "laps + 1")]), "E"],
        [("S", "tick"), ("tick", "B"), ("B", "C"), ("C", "B", "n < 300"),
         ("C", "D", "otherwise"), ("D", "tick", "laps < 50"), ("D", "E", "otherwise")],
        data=[_int("n"), _int("laps")]))
    result = Simulation(package).run(until=100 * 3600)
    assert result.summary["instances"]["completed"] == 1


def test_a_limit_that_is_no_positive_integer_falls_back_to_the_default(
        monkeypatch: pytest.MonkeyPatch) -> None:
    for raw in ("", "zero", "-5", "0"):
        monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", raw)
        assert max_instant_steps() == MAX_INSTANT_STEPS
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "1234")
    assert Simulation(pkg(proc("p", ["a"]))).max_instant_steps == 1234


@pytest.mark.usefixtures("small_limit")
def test_simulate_raises_it_too() -> None:
    with pytest.raises(ZeroTimeCycleError, match="process 'looping'"):
        opspec.run(load_spec(SPECS / "loop.xpdl"), days=1)


def lasts(seconds: float) -> Distribution:
    return Distribution(kind="constant", parameters=(("value", seconds),))


def _int(name: str) -> Any:
    from builders import field

    return field(name, 0)
