"""Scripted users from files, simulated devices, the step API and wall-clock mode."""

from __future__ import annotations

import json
import threading
from pathlib import Path

import pytest
from builders import act, catch, manual, pkg, proc
from engine_runs import completed, events, run

from opspec.engine.builtin_performers import ScriptedUser, SimulatedDevice, Step
from opspec.engine.config import EngineConfig
from opspec.engine.registry import PerformerRegistry
from opspec.engine.simulation import Simulation
from opspec.errors import ConfigurationError
from opspec.model import DeclaredDistribution as Distribution


def _two_step() -> object:
    return pkg(proc("p", [manual("a"), manual("b")], [("a", "b")]))


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_scripted_user_loads_from_json_or_toml(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"script{suffix}"
    if suffix == ".json":
        path.write_text(json.dumps({"steps": [{"after": 5, "do": "complete a"},
                                              {"after": 7, "do": "complete b"}]}))
    else:
        path.write_text('[[steps]]\nafter = 5\ndo = "complete a"\n'
                        '[[steps]]\nafter = 7\ndo = "complete b"\n')
    user = ScriptedUser.load(path)
    result = run(_two_step(), performers={"user": user})
    assert [e.time for e in events(result, "activity.completed")] == [5.0, 12.0]
    assert user.log == [(5.0, "complete", "a"), (12.0, "complete", "b")]


def test_script_errors_name_the_step(tmp_path: Path) -> None:
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"steps": [{"after": 5, "do": "dance a"}]}))
    with pytest.raises(ConfigurationError, match=r"bad.json: steps\[0\].*not understood"):
        ScriptedUser.load(path)
    path.write_text(json.dumps({"steps": [{"when": 5, "do": "complete a"}]}))
    with pytest.raises(ConfigurationError, match=r"steps\[0\]: unknown step key"):
        ScriptedUser.load(path)


def test_step_parses_absolute_times_data_and_exceptions() -> None:
    assert Step.parse("at 30", "complete a x=3 ok=true") == Step(
        "complete", "a", 30.0, True, {"x": 3, "ok": True})
    assert Step.parse(2, "fail a jammed").exception == "jammed"


def test_simulated_device_completes_after_the_declared_duration() -> None:
    model = pkg(proc("p", [act("move", auto_run=False, performer="motor",
                               duration=Distribution(kind="constant",
                                                     parameters=(("value", 3.0),)))]))
    result = run(model, performers=PerformerRegistry(default_device=SimulatedDevice()))
    assert events(result, "activity.completed")[0].time == 3.0


def test_step_api_peeks_and_steps_one_event_at_a_time() -> None:
    model = pkg(proc("p", [catch("w", "timer", seconds=4.0), "after"], [("w", "after")]))
    sim = Simulation(model, keep_trace=True)
    assert sim.peek() == 4.0
    assert sim.step() is True
    assert sim.env.now == 4.0 and completed(sim.result()) == ["w", "after"]
    assert sim.step() is False


def test_post_runs_external_input_on_the_engine_thread_before_the_next_step() -> None:
    model = pkg(proc("p", [catch("w", "message", "button"), "after"], [("w", "after")]),
                proc("clock", ["tick"], start="period:1"))
    sim = Simulation(model, keep_trace=True)
    sim.run(until=2.5)
    thread = threading.Thread(target=lambda: sim.post(lambda: sim.raise_trigger("button")))
    thread.start()
    thread.join()
    sim.step()
    assert completed(sim.result(), "p") == ["w", "after"]


def test_wall_clock_mode_runs_at_the_requested_speed_and_reports_drift() -> None:
    model = pkg(proc("tick", ["a"], start="period:10"))
    result = Simulation(model, EngineConfig(realtime=True, speed=2000.0)).run(until=50.0)
    drift = result.summary["drift"]
    assert drift["events"] >= 5 and drift["speed"] == 2000.0
    assert drift["max_s"] < 1.0
    assert result.summary["instances"]["started"] == 6
