"""One front hall: every door fills one :class:`opspec.request.RunRequest`, so the same request
gives the same trace through every door that has the option, and a bad request is refused
with the same message through every door.

One equivalence test per option of a request (nothing, the seed, the days, an end time, a
user model, a script, nobody, an engine configuration), and the four drifts issue 27 found
between the doors, each now a test: a spec ``opspec validate`` refuses (two OTHERWISE
transitions out of one XOR split) is refused everywhere; a compiled ``.wfs`` runs through
``simulate()`` as through ``opspec run``; with no user given every door uses the spec's
companion user model; a script naming an activity the spec lacks is refused everywhere.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import tomli_w
from test_front_doors import DOOR_ONLY, _file, _plain, _same

import opspec
from opspec import runs
from opspec.cli import main
from opspec.errors import OpspecError
from opspec.testing import simulate
from opspec.testing.scenario import load_scenarios, run_scenario

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
COMPANION = ROOT / "specs" / "medication_dispenser.users.toml"
LATE = 'otherwise = "complete"\nsteps = [["after trg_2 400s", "press_report"]]\n'


@dataclass(frozen=True)
class Ask:
    """One request, as a person would make it at any door."""

    seed: int = 7
    days: float | None = 1.0
    until: float | None = None
    user_model: str | None = None
    script: str | None = None           # a script file's name in the test's folder
    no_user: bool = False
    engine: dict[str, Any] | None = None


def _events(objects: Any) -> list[dict[str, Any]]:
    return [_plain(e) for e in objects if e.get("kind") not in DOOR_ONLY]


def _script(folder: Path, ask: Ask) -> Path | None:
    if ask.script is None:
        return None
    path = folder / ask.script
    path.write_text(LATE, encoding="utf-8")
    return path


def _engine_file(folder: Path, ask: Ask) -> list[str]:
    if ask.engine is None:
        return []
    path = folder / "engine.toml"
    path.write_text(tomli_w.dumps(ask.engine), encoding="utf-8")
    return ["--engine-config", str(path)]


# ---------------------------------------------------------------------------- the doors


def cli_run(folder: Path, spec: Path, ask: Ask) -> list[dict]:
    trace = folder / "run.jsonl"
    args = ["run", str(spec), "--seed", str(ask.seed), "--trace", str(trace),
            "--timeline", "none", *_engine_file(folder, ask)]
    args += ["--days", str(ask.days)] if ask.days is not None else []
    args += ["--until", str(ask.until)] if ask.until is not None else []
    args += ["--user-model", ask.user_model] if ask.user_model else []
    script = _script(folder, ask)
    args += ["--script", str(script)] if script else []
    args += ["--no-user"] if ask.no_user else []
    assert main(args) in (0, 1)
    header, events = _file(trace)
    assert header["seed"] == ask.seed
    return _events(events)


def python_run(folder: Path, spec: Path, ask: Ask) -> list[dict]:
    outcome = opspec.run(spec, seed=ask.seed, days=ask.days, until=ask.until,
                         user_model=ask.user_model, script=_script(folder, ask),
                         no_user=ask.no_user, config=ask.engine)
    assert outcome.trace is not None
    return _events(e.to_json() for e in outcome.trace)


def python_simulate(folder: Path, spec: Path, ask: Ask) -> list[dict]:
    result = simulate(spec, seed=ask.seed, days=ask.days, until=ask.until,
                      user_model=ask.user_model, script=_script(folder, ask),
                      no_user=ask.no_user, engine_config=ask.engine, keep_trace=True)
    return _events(e.to_json() for e in result.trace)


def scenario_file(folder: Path, spec: Path, ask: Ask,
                  monkeypatch: pytest.MonkeyPatch) -> list[dict]:
    """A ``*.scenario.toml`` file whose ``given`` spells the request."""
    from opspec.testing import simulation

    given: dict[str, Any] = {"seed": ask.seed}
    for key in ("days", "until", "user_model", "engine"):
        if getattr(ask, key) is not None:
            given[key] = getattr(ask, key)
    script = _script(folder, ask)
    if script is not None:
        given["script"] = script.name
    path = folder / "hall.scenario.toml"
    path.write_text(tomli_w.dumps({"spec": spec.as_posix(), "scenario": [
        {"name": "the request", "given": given, "then": ["eventually process timer_workflow"]}]}),
        encoding="utf-8")
    seen: list[Any] = []
    real = simulation.simulate

    def keep(*args: Any, **kwargs: Any) -> Any:
        seen.append(real(*args, **{**kwargs, "keep_trace": True}))
        return seen[-1]

    monkeypatch.setattr(simulation, "simulate", keep)
    (scenario,) = load_scenarios(path).scenarios
    run_scenario(scenario, spec)
    return _events(e.to_json() for e in seen[0].trace)


def cli_evaluate(folder: Path, spec: Path, ask: Ask) -> list[dict]:
    out = folder / "evaluation"
    args = ["evaluate", str(spec), "--users", "1", "--seed", str(ask.seed), "--workers", "1",
            "--export", "jsonl", "--case", "user", "--out", str(out), "--json",
            *_engine_file(folder, ask)]
    args += ["--days", str(ask.days)] if ask.days is not None else []
    args += ["--user-model", ask.user_model] if ask.user_model else []
    # the trace is what is compared; the report (almost all of a one-user evaluation's CPU)
    # is drawn and read by tests/evaluation and tests/evaluation_output
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("opspec.evaluation.report.write_report",
                      lambda store, *_args, **_kwargs: store.folder / "report.html")
        assert main(args) == 0
    header, events = _file(out / "traces.jsonl")
    assert header["seed"] == ask.seed
    return _events(events)


def walkthrough(folder: Path, spec: Path, ask: Ask) -> list[dict]:
    """The walkthrough's session with the person's lane handed over to the request's user
    model from the start (its first hand-over is user 0), or replaying the script."""
    from opspec.commands.walkthrough import _model_factory
    from opspec.request import RunRequest, prepare
    from opspec.tui.replay import load_recording
    from opspec.tui.session import WalkSession

    script = _script(folder, ask)
    prepared = prepare(RunRequest(spec, seed=ask.seed, days=ask.days,
                                  user_model=ask.user_model))
    model = prepared.user.source if prepared.user.kind == "model" else None
    kept: list[dict] = []
    session = WalkSession(prepared.compiled, seed=ask.seed, days=ask.days,
                          model_factory=_model_factory(model, ask.seed) if model else None,
                          replay=load_recording(script, prepared.compiled) if script else None)
    session.listeners.append(lambda event: kept.append(event.to_json()))
    if model is not None and script is None:
        assert session.hand_over()
    while not session.ended:
        session.run_to(session.horizon)
    assert session.failure is None
    boot = [e.to_json() for e in session.events if e.kind == "run.started"]
    session.close()
    return _events([*boot, *kept])


# which doors take which part of a request (evaluate: --days, --seed, --user-model and
# --engine-config; the walkthrough: --seed, --days, a model to hand over to, a replay)
TAKES = {
    "evaluate": {"seed", "days", "user_model", "engine"},
    "walkthrough": {"seed", "days", "user_model", "script"},
    "scenario": {"seed", "days", "until", "user_model", "script", "engine"},
}
OPTIONS = {
    "nothing": Ask(),
    "seed": Ask(seed=2**40 + 3),
    "days": Ask(days=2.0),
    "until": Ask(days=None, until=30_000.0),
    "user_model": Ask(user_model="dispenser-reference"),
    "script": Ask(script="late.toml"),
    "no_user": Ask(no_user=True),
    "engine": Ask(engine={"processor_model": "pooled", "workers": 1, "switch_cost": 0.01}),
}


def _given(ask: Ask) -> set[str]:
    base = Ask()
    return {key for key in ("seed", "days", "until", "user_model", "script", "no_user",
                            "engine") if getattr(ask, key) != getattr(base, key)
            and getattr(ask, key) is not None and getattr(ask, key) is not False}


@pytest.mark.parametrize("option", OPTIONS)
def test_the_same_request_is_the_same_trace_through_every_door(
        option: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    ask = OPTIONS[option]
    doors: dict[str, list[dict]] = {
        "opspec run": cli_run(tmp_path, DISPENSER, ask),
        "opspec.run": python_run(tmp_path, DISPENSER, ask),
        "simulate": python_simulate(tmp_path, DISPENSER, ask),
    }
    given = _given(ask)
    if given <= TAKES["scenario"]:
        doors["scenario"] = scenario_file(tmp_path, DISPENSER, ask, monkeypatch)
    if given <= TAKES["evaluate"]:
        doors["evaluate"] = cli_evaluate(tmp_path, DISPENSER, ask)
    if given <= TAKES["walkthrough"]:
        doors["walkthrough"] = walkthrough(tmp_path, DISPENSER, ask)
    _same(doors)
    trace = doors["opspec run"]
    ends = max(e["time"] for e in trace)
    if ask.until is not None:
        assert ends <= ask.until
    else:
        assert (ask.days - 1) * 86_400 < ends <= ask.days * 86_400
    reports = [e for e in trace if e["kind"] == "activity.completed"
               and e.get("activity") == "press_report"]
    assert (reports == []) == ask.no_user       # nobody reports only when nobody is there


# ---------------------------------------------------------------------------- the drifts


@pytest.fixture(scope="module")
def two_defaults(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The dispenser with its evening branch made a second OTHERWISE out of one XOR split."""
    folder = tmp_path_factory.mktemp("two_defaults")
    text = DISPENSER.read_text(encoding="utf-8")
    evening = ('<Condition Type="CONDITION"><Expression>hour &lt; 20</Expression>'
               "</Condition></Transition>")
    assert text.count(evening) == 1
    spec = folder / "two_defaults.xpdl"
    spec.write_text(text.replace(evening, '<Condition Type="OTHERWISE"/></Transition>'),
                    encoding="utf-8")
    shutil.copy(COMPANION, folder / "two_defaults.users.toml")
    return spec


def _refusal(call: Any) -> str:
    with pytest.raises((OpspecError, pytest.fail.Exception)) as caught:
        call()
    return str(caught.value)


def test_a_spec_validate_refuses_is_refused_by_every_door_with_the_same_message(
        two_defaults: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path,
        request: pytest.FixtureRequest) -> None:
    """BPMN 2.0 (formal/2011-01-03) 10.5.2, Exclusive Gateway: "A default path can
    optionally be identified, to be taken in the event that none of the conditional Sequence
    Flows evaluate to true" - one default path, which XPDL writes as the OTHERWISE
    transition; ``opspec validate`` refuses two, and so must every door that runs a spec."""
    from opspec.testing.plugin import Simulator, load_cached
    from opspec.xpdl.loader import load_spec

    assert main(["validate", str(two_defaults)]) == 1
    said = [line for line in capsys.readouterr().out.splitlines() if ": error: " in line]
    assert len(said) == 1 and "2 OTHERWISE transitions" in said[0]
    where, message = said[0].split(": error: ")
    message = message.split(" (")[0]            # the hint follows in brackets
    assert where.endswith("two_defaults.xpdl:159")
    messages = {}
    for command in (["run"], ["evaluate", "--users", "1", "--out", str(tmp_path / "e")],
                    ["walkthrough", "--no-record"], ["check", "--schedulability"]):
        status = main([command[0], str(two_defaults), *command[1:]])
        said_now = capsys.readouterr()
        messages[command[0]] = said_now.err + said_now.out   # check reports on stdout
        assert status == 1, command
    scenario = tmp_path / "two.scenario.toml"
    scenario.write_text(f'spec = "{two_defaults.as_posix()}"\n[[scenario]]\nname = "x"\n'
                        'then = ["doses_due == 4"]\n', encoding="utf-8")
    messages.update({
        "opspec.run": _refusal(lambda: opspec.run(two_defaults)),
        "simulate(path)": _refusal(lambda: simulate(two_defaults)),
        # a package read without validation (load_spec reads, it does not judge)
        "simulate(package)": _refusal(lambda: simulate(load_spec(two_defaults))),
        "opspec.run(package)": _refusal(lambda: opspec.run(load_spec(two_defaults))),
        "pytest spec fixture": _refusal(lambda: load_cached(two_defaults, request.config)),
        "pytest simulate fixture": _refusal(
            lambda: Simulator(request.config, None, 0)(two_defaults)),
        "scenario file": _refusal(lambda: load_scenarios(scenario)),
        # the run builder's own doors: the gate is in the loader, so no caller skips it
        "runs.load(path)": _refusal(lambda: runs.load(two_defaults)),
        "runs.build(path)": _refusal(lambda: runs.build(two_defaults)),
        "runs.build(package)": _refusal(lambda: runs.build(load_spec(two_defaults))),
    })
    for door, text in messages.items():
        assert message in text, f"{door} said: {text}"
        if door not in ("simulate(package)", "opspec.run(package)", "check",
                        "runs.build(package)"):
            assert where in text, f"{door} did not name {where}: {text}"


def test_a_compiled_wfs_runs_through_every_door(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    wfs = tmp_path / "dispenser.wfs"
    assert main(["compile", str(DISPENSER), "-o", str(wfs)]) == 0
    ask = Ask(user_model=str(COMPANION))
    doors = {
        "opspec run": cli_run(tmp_path, wfs, ask),
        "opspec.run": python_run(tmp_path, wfs, ask),
        "simulate": python_simulate(tmp_path, wfs, ask),
        "scenario": scenario_file(tmp_path, wfs, ask, monkeypatch),
        "walkthrough": walkthrough(tmp_path, wfs, ask),
        "the XPDL itself": cli_run(tmp_path, DISPENSER, ask),
    }
    _same(doors)


def test_with_no_user_given_every_door_uses_the_companion_user_model(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """The drift issue 27 measured: the dispenser, seed 3, 2 days, no user given, reported
    a mean report latency of 126.3 s through one door and 0.0 s through another."""
    ask = Ask(seed=3, days=2.0)
    assert main(["run", str(DISPENSER), "--seed", "3", "--days", "2", "--json"]) == 0
    said = json.loads(capsys.readouterr().out)["metrics"]["report_latency_s"]["mean"]
    latencies = {
        "opspec run": said,
        "opspec.run": opspec.run(DISPENSER, seed=3, days=2).metrics[
            "report_latency_s"]["mean"],
        "simulate": simulate(DISPENSER, seed=3, days=2).value("report_latency_s"),
    }
    assert len(set(latencies.values())) == 1, latencies
    assert latencies["simulate"] == pytest.approx(126.3, abs=0.05)
    # the same run: the trace of simulate with no user is that of the companion model,
    # through the scenario file and the evaluation too
    companion = Ask(seed=3, days=2.0, user_model=str(COMPANION))
    _same({"simulate": python_simulate(tmp_path, DISPENSER, ask),
           "simulate(companion)": python_simulate(tmp_path, DISPENSER, companion),
           "scenario": scenario_file(tmp_path, DISPENSER, ask, monkeypatch),
           "evaluate": cli_evaluate(tmp_path, DISPENSER, ask),
           "walkthrough": walkthrough(tmp_path, DISPENSER, ask)})


def test_a_script_naming_an_activity_the_spec_lacks_is_refused_by_every_door(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from opspec.testing import load_script

    script = tmp_path / "typo.toml"
    script.write_text('steps = [["after trg_2 90s", "press_reprot"]]\n', encoding="utf-8")
    scenario = tmp_path / "typo.scenario.toml"
    scenario.write_text(f'spec = "{DISPENSER.as_posix()}"\n[[scenario]]\nname = "typo"\n'
                        'given = { script = "typo.toml" }\nthen = ["doses_due == 4"]\n',
                        encoding="utf-8")
    messages = {}
    for command in ("run", "walkthrough"):
        option = "--script" if command == "run" else "--replay"
        assert main([command, str(DISPENSER), option, str(script)]) == 2
        messages[command] = capsys.readouterr().err
    messages.update({
        "opspec.run(path)": _refusal(lambda: opspec.run(DISPENSER, script=script)),
        "opspec.run(Script)": _refusal(lambda: opspec.run(DISPENSER,
                                                          script=load_script(script))),
        "opspec.run(steps)": _refusal(lambda: opspec.run(
            DISPENSER, script=[("after trg_2 90s", "press_reprot")])),
        "simulate": _refusal(lambda: simulate(DISPENSER, script=script)),
        "scenario file": _refusal(lambda: load_scenarios(scenario)),
    })
    first = messages["run"]
    assert "press_reprot" in first and "press_report" in first      # what it has instead
    for door, text in messages.items():
        assert "'press_reprot'" in text and "press_report" in text, f"{door}: {text}"


def test_a_request_cannot_change_once_a_door_has_filled_it() -> None:
    """A request is immutable all the way down (its performers, listeners and params too),
    and a prepared run takes a door's listeners but not a new seed, spec or user."""
    import dataclasses

    from opspec.errors import ConfigurationError
    from opspec.request import RunRequest, prepare

    performers: dict[str, Any] = {}
    request = RunRequest(DISPENSER, seed=3, performers=performers, listeners=[print])
    performers["alarm"] = object()                 # the door's dict changes afterwards...
    assert "alarm" not in request.performers       # ...the request does not
    with pytest.raises(dataclasses.FrozenInstanceError):
        request.seed = 4                           # type: ignore[misc]
    with pytest.raises(TypeError):
        request.performers["alarm"] = object()     # type: ignore[index]
    prepared = prepare(request)
    assert prepared.seed == 3 and prepared.horizon == 86_400.0
    assert prepared.user.kind == "model"           # the companion SPEC.users.toml
    assert prepared.but(listeners=()).request.listeners == ()
    for decided in ({"seed": 4}, {"spec": DISPENSER}, {"no_user": True}):
        with pytest.raises(ConfigurationError, match="decided"):
            prepared.but(**decided)


LOAN = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="ask"/>
    <bpmn:exclusiveGateway id="ask"/>
    <bpmn:sequenceFlow id="yes" sourceRef="ask" targetRef="done">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &gt; 50}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="no" sourceRef="ask" targetRef="remind">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &lt;= 50}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:endEvent id="done"/>
    <bpmn:endEvent id="remind"/>
  </bpmn:process>
</bpmn:definitions>
"""


def test_a_value_for_a_name_the_spec_does_not_have_is_refused_by_every_door(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # a misspelt run input was set where nothing reads it: the run went on with the diagram's
    # own fallback and said nothing (the API's params; --param refused it already)
    diagram = tmp_path / "loan.bpmn"
    diagram.write_text(LOAN, encoding="utf-8")
    assert main(["run", str(diagram), "--param", "scroe=70"]) == 2
    messages = {"run --param": capsys.readouterr().err,
                "opspec.run": _refusal(lambda: opspec.run(diagram, params={"scroe": 70})),
                "simulate": _refusal(lambda: simulate(diagram, params={"scroe": 70}))}
    for door, text in messages.items():
        assert "no package data field 'scroe' (did you mean 'score'?)" in text, f"{door}: {text}"
    # the name it has is taken, and decides the route
    done = opspec.run(diagram, params={"score": 70}, keep_trace=True)
    assert "done" in {e.activity for e in done.trace if e.kind == "activity.completed"}
