"""Every front door builds the same run: the same spec, seed and user give user 0 the same
trace through ``opspec run --trace``, ``opspec evaluate --export jsonl``, ``simulate()``, a
scenario file, the walkthrough session and ``opspec.run`` (opspec.runs builds them all).

Three specs: the medication dispenser with its stochastic user model (and with a script), a
robot whose mode change loads the new mode's workflows from another file, and a device whose
activities take random durations (the engine's named streams, scoped by the user).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import opspec
from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.testing import simulate
from opspec.testing.scenario import load_scenarios, run_scenario
from opspec.tui.replay import load_recording
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
SEED = 7

#: events only a front door adds: the walkthrough records each action of a handed-over model
#: (``walkthrough.action``) and is stepped, never run, so it has no ``run.ended``; evaluation
#: files open each user's case with ``case.started``
DOOR_ONLY = frozenset({"walkthrough.action", "run.ended", "case.started"})


def _plain(event: dict[str, Any]) -> dict[str, Any]:
    """An event as JSON, without what numbers or files it (seq, case)."""
    out = json.loads(json.dumps(event, default=str))
    out.pop("seq", None)
    out.pop("case", None)
    return out


def _events(objects: Any) -> list[dict[str, Any]]:
    return [_plain(e) for e in objects if e.get("kind") not in DOOR_ONLY]


def _file(path: Path) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    lines = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()
             if line.strip()]
    return lines[0], lines[1:]


# ---------------------------------------------------------------------------- the doors


def via_run(tmp_path: Path, spec: Path, user: list[str], days: float | None) -> list[dict]:
    trace = tmp_path / "run.jsonl"
    length = ["--days", str(days)] if days is not None else []
    status = main(["run", str(spec), "--seed", str(SEED), *user, *length,
                   "--trace", str(trace), "--timeline", "none"])
    assert status == 0
    header, events = _file(trace)
    assert header["seed"] == SEED and isinstance(header["seed"], int)
    return _events(events)


def via_evaluate(tmp_path: Path, spec: Path, user: list[str], days: float | None,
                 users: int = 2) -> dict[str, list[dict]]:
    out = tmp_path / "evaluation"
    length = ["--days", str(days)] if days is not None else []
    status = main(["evaluate", str(spec), "--users", str(users), "--seed", str(SEED),
                   *user, *length, "--workers", "1", "--export", "jsonl", "--out", str(out),
                   "--json"])
    assert status == 0
    header, events = _file(out / "traces.jsonl")
    assert header["seed"] == SEED and isinstance(header["seed"], int)
    cases: dict[str, list[dict]] = {}
    for event in events:
        cases.setdefault(event["case"], []).append(event)
    return {case: _events(found) for case, found in cases.items()}


def via_simulate(spec: Path, days: float | None, **user: Any) -> list[dict]:
    result = simulate(spec, seed=SEED, days=days, keep_trace=True, **user)
    return _events(e.to_json() for e in result.trace)


def via_opspec_run(spec: Path, days: float | None, **user: Any) -> list[dict]:
    outcome = opspec.run(spec, seed=SEED, days=days, **user)
    assert outcome.trace is not None
    return _events(e.to_json() for e in outcome.trace)


def via_scenario(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, spec: Path, given: str,
                 then: str) -> list[dict]:
    """A scenario file runs through simulate(): its given keys must make the same run."""
    from opspec.testing import simulation

    seen: list[Any] = []
    real = simulation.simulate

    def keep(*args: Any, **kwargs: Any) -> Any:
        kwargs["keep_trace"] = True
        seen.append(real(*args, **kwargs))
        return seen[-1]

    path = tmp_path / "doors.scenario.toml"
    path.write_text(f'spec = "{spec.as_posix()}"\n\n[[scenario]]\nname = "the same run"\n'
                    f"given = {{ seed = {SEED}, {given} }}\nthen = [{json.dumps(then)}]\n",
                    encoding="utf-8")
    document = load_scenarios(path)
    monkeypatch.setattr(simulation, "simulate", keep)
    failures = run_scenario(document.scenarios[0], compile_package(open_spec(spec)))
    assert failures == []
    (result,) = seen
    return _events(e.to_json() for e in result.trace)


def via_walkthrough(tmp_path: Path, spec: Path, days: float | None, *,
                    model: Path | None = None, script: Path | None = None) -> list[dict]:
    """The walkthrough session, the lane handed to the model from the start (the model's
    first hand-over is user 0), or replaying a script; stepped to the end of the run."""
    from opspec.commands.walkthrough import _model_factory
    from opspec.usermodels import load_user_model

    compiled = compile_package(open_spec(spec))
    record = tmp_path / "walk.json"
    session = WalkSession(
        compiled, seed=SEED, days=days, record=None if script else record,
        model_factory=_model_factory(load_user_model(model), SEED) if model else None,
        replay=load_recording(script, compiled) if script else None)
    trace_file = tmp_path / "walk.trace.jsonl"
    if script:      # a replay records nothing: keep its trace with a listener
        kept: list[dict] = []
        session.listeners.append(lambda event: kept.append(event.to_json()))
    if model is not None:
        assert session.hand_over()
    while not session.ended:
        session.run_to(session.horizon)
    assert session.failure is None
    session.close()
    if script:
        boot = [e.to_json() for e in session.events if e.kind == "run.started"]
        return _events([*boot, *kept])
    header, events = _file(trace_file)
    assert header["seed"] == SEED and isinstance(header["seed"], int)
    return _events(events)


def _same(doors: dict[str, list[dict]]) -> None:
    (first_name, first), *others = doors.items()
    assert first, f"{first_name} traced nothing"
    for name, events in others:
        assert len(events) == len(first), f"{name}: {len(events)} events, {first_name}: " \
                                          f"{len(first)}"
        for mine, theirs in zip(events, first, strict=True):
            assert mine == theirs, f"{name} differs from {first_name}"


# ---------------------------------------------------------------------------- the specs


def test_the_dispenser_with_its_user_model_is_one_run_through_every_door(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    model = ["--user-model", str(USERS)]
    doors = {
        "run": via_run(tmp_path, DISPENSER, model, 1),
        "evaluate": via_evaluate(tmp_path, DISPENSER, model, 1)["A/0"],
        "simulate": via_simulate(DISPENSER, 1, user_model=USERS),
        "opspec.run": via_opspec_run(DISPENSER, 1, user_model=USERS),
        "scenario": via_scenario(tmp_path, monkeypatch, DISPENSER,
                                 f'days = 1, user_model = "{USERS.as_posix()}"',
                                 "doses_due == 4"),
        "walkthrough": via_walkthrough(tmp_path, DISPENSER, 1, model=USERS),
    }
    _same(doors)
    # the user model drew: reports come at different times after each alarm
    reports = {round(e["time"] % 3600, 3) for e in doors["run"]
               if e["kind"] == "activity.completed" and e.get("activity") == "press_report"}
    assert len(reports) == 4


def test_the_dispenser_with_a_script_is_one_run_through_every_door(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    script = tmp_path / "late.toml"
    script.write_text('otherwise = "complete"\nsteps = [["after trg_2 400s", "press_report"]]\n',
                      encoding="utf-8")
    from opspec.testing import load_script

    doors = {
        "run": via_run(tmp_path, DISPENSER, ["--script", str(script)], 1),
        "simulate": via_simulate(DISPENSER, 1, script=script),
        "opspec.run": via_opspec_run(DISPENSER, 1, script=load_script(script)),
        "scenario": via_scenario(tmp_path, monkeypatch, DISPENSER,
                                 f'days = 1, script = "{script.as_posix()}"',
                                 "doses_due == 4"),
        "walkthrough": via_walkthrough(tmp_path, DISPENSER, 1, script=script),
    }
    _same(doors)
    assert any(e["kind"] == "deadline.expired" for e in doors["run"])   # 400 s: late


# a robot that cleans, then docks: the dock mode's workflow is in another file
ROBOT = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" xmlns:opspec="urn:opspec:sisarl:1"
         Id="{id}" Name="{id}">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion></PackageHeader>
  <WorkflowProcesses>{processes}</WorkflowProcesses>
  <ExtendedAttributes>{attributes}</ExtendedAttributes>
</Package>
"""


def _process(pid: str, activity: str, **directives: str) -> str:
    attrs = "".join(f'<ExtendedAttribute Name="opspec:{k}" Value="{v}"/>'
                    for k, v in directives.items())
    return (f'<WorkflowProcess Id="{pid}"><ProcessHeader/><Activities>{activity}</Activities>'
            f"<ExtendedAttributes>{attrs}</ExtendedAttributes></WorkflowProcess>")


def _takes(aid: str, duration: str) -> str:
    return (f'<Activity Id="{aid}"><Implementation><No/></Implementation><ExtendedAttributes>'
            f'<ExtendedAttribute Name="opspec:Duration" Value="{duration}"/>'
            f"</ExtendedAttributes></Activity>")


def _robot(tmp_path: Path) -> Path:
    change = ('<Activity Id="go_dock"><Implementation><No/></Implementation>'
              '<ExtendedAttributes><ExtendedAttribute Name="opspec:BuiltIn">'
              '<opspec:ModeChange To="dock"/></ExtendedAttribute></ExtendedAttributes>'
              "</Activity>")
    modes = ('<ExtendedAttribute Name="opspec:Modes"><opspec:Mode Id="clean" Initial="true"/>'
             '<opspec:Mode Id="dock" Source="docking.xpdl"/></ExtendedAttribute>'
             '<ExtendedAttribute Name="opspec:RunLength" Value="PT10S"/>')
    (tmp_path / "docking.xpdl").write_text(ROBOT.format(
        id="docking", attributes="",
        processes=_process("park", _takes("halt", "uniform(0.1, 0.5)"), Period="1s")),
        encoding="utf-8")
    spec = tmp_path / "robot.xpdl"
    spec.write_text(ROBOT.format(id="robot", attributes=modes, processes="".join([
        _process("clean", _takes("sweep", "exponential(0.3)"), Period="1s", Mode="clean"),
        _process("watch", change, StartTrigger="timer:after 4.5s")])), encoding="utf-8")
    return spec


def test_a_mode_change_loads_the_new_modes_workflows_through_every_door(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    spec = _robot(tmp_path)
    doors = {
        "run": via_run(tmp_path, spec, ["--no-user"], None),
        "evaluate": via_evaluate(tmp_path, spec, [], None)["A/0"],
        "simulate": via_simulate(spec, None, script=[]),
        "opspec.run": via_opspec_run(spec, None),
        "scenario": via_scenario(tmp_path, monkeypatch, spec, "users = 1",
                                 "eventually activity go_dock"),
        "walkthrough": via_walkthrough(tmp_path, spec, None),
    }
    _same(doors)
    run = doors["run"]
    assert [e["data"] for e in run if e["kind"] == "mode.changed"] == [
        {"from": "clean", "to": "dock"}]
    parked = [e["time"] for e in run if e["kind"] == "process.started"
              and e["process"] == "park"]
    assert parked == [5.0, 6.0, 7.0, 8.0, 9.0]       # loaded at 4.5 s, from docking.xpdl
    assert max(e["time"] for e in run) <= 10.0        # opspec:RunLength PT10S


def test_random_durations_draw_the_same_numbers_for_user_0_through_every_door(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    spec = tmp_path / "busy.xpdl"
    spec.write_text(ROBOT.format(id="busy", attributes=(
        '<ExtendedAttribute Name="opspec:RunLength" Value="PT20S"/>'), processes=_process(
        "work", _takes("grind", "lognormal(0.5, 0.8)"), Period="2s")), encoding="utf-8")
    cases = via_evaluate(tmp_path, spec, [], None, users=2)
    doors = {
        "run": via_run(tmp_path, spec, ["--no-user"], None),
        "evaluate": cases["A/0"],
        "simulate": via_simulate(spec, None, script=[]),
        "opspec.run": via_opspec_run(spec, None),
        "scenario": via_scenario(tmp_path, monkeypatch, spec, "users = 1",
                                 "eventually process work"),
        "walkthrough": via_walkthrough(tmp_path, spec, None),
    }
    _same(doors)

    def ends(events: list[dict]) -> list[float]:
        return [e["time"] for e in events if e["kind"] == "activity.completed"
                and e.get("activity") == "grind"]

    assert len({round(t % 2.0, 9) for t in ends(doors["run"])}) > 1     # durations drawn
    assert ends(cases["A/1"]) != ends(doors["run"])    # user 1 has streams of its own
