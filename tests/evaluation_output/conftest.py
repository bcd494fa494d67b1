"""Fixtures: real engine traces of the bundled medication dispenser."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.trace import TraceEvent

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


def run_dispenser(script: list[tuple[float, str]], *, seed: int = 1,
                  until: float = 86_400.0) -> list[TraceEvent]:
    """Every trace event of one simulated day of the dispenser with a scripted user."""
    loader = pytest.importorskip("opspec.xpdl.loader")
    from opspec.engine.builtin_performers import ScriptedUser
    from opspec.engine.simulation import Simulation
    from opspec.engine.trace_sinks import MemorySink

    if not SPEC.exists():
        pytest.skip("specs/medication_dispenser.xpdl is not there")
    sink = MemorySink()
    user = ScriptedUser(script, default="omit")
    Simulation(loader.load_spec(SPEC), performers={"user": user}, seed=seed,  # type: ignore[arg-type]
               listeners=[sink]).run(until=until)
    return sink.events


@pytest.fixture(scope="session")
def dispenser_day() -> list[TraceEvent]:
    """A day in which the user takes the morning dose after 90 s, then hears no alarm."""
    return run_dispenser([(0, "complete hear_alarm"), (90, "complete walk_to_dispenser"),
                          (0, "choose press_report"), (20, "complete take_pill")])
