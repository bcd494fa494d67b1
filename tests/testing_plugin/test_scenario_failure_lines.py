"""Every failure of a scenario run, and every mistake in a script written inside a scenario
file, is placed at ``file:line: key``: the line its expectation, step or table is written on,
so that a device designer need not count tables (it read ``file: scenario[2].then[1]``)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from opspec.errors import ConfigurationError


def _literal(pattern: str) -> str:
    """An fnmatch pattern where '[' is literal ('*' and '?' keep their meaning)."""
    return pattern.replace("[", "[[]")


#: a file in a folder below the rootdir: the path is shown as pytest names it
FAILING = '''\
spec = "../dispenser.xpdl"

[[scenario]]
name = "prompt user"
given = { script = [["after trg_2 90s", "press_report"]], until = "09:00" }
then = ["doses_taken == 1"]

[[scenario]]
name = "silent user"
given.script = [["never", "press_report"]]
given.until = "09:00"
then = [
  "alarms == 3",
  "alarms == 1",
  "caregiver_notified == 1",
  "eventually activity dispense",
]

[[scenario]]
name = "one line"
given.until = "09:00"
then = "doses_taken == 7"
'''


def test_each_failing_expectation_is_placed_at_its_line(project: pytest.Pytester) -> None:
    (project.path / "specs" / "tests").mkdir()
    (project.path / "specs" / "tests" / "pill.scenario.toml").write_text(FAILING)
    result = project.runpytest()
    result.assert_outcomes(passed=1, failed=2)
    result.stdout.fnmatch_lines([_literal(line) for line in [
        "specs/tests/pill.scenario.toml:14: scenario[1].then[1]: expected alarms == 1",
        "*",
        ("specs/tests/pill.scenario.toml:16: scenario[1].then[3]: expected eventually "
         "activity dispense"),
        "*",
        # a then written as one string is its line (then[0] is how the file counts it)
        "specs/tests/pill.scenario.toml:22: scenario[2].then[0]: expected doses_taken == 7"]])


def test_a_scenario_that_cannot_run_is_placed_at_its_table(project: pytest.Pytester) -> None:
    # what the run refuses is placed at the scenario's table; a params name the spec lacks is
    # refused when the file is collected (test_scenario_given_names.py), so here it is given
    # after collection, as a spec changed since would make it
    (project.path / "params.scenario.toml").write_text(
        'spec = "specs/dispenser.xpdl"\n\n[[scenario]]\nname = "ok"\nthen = ["alarms >= 0"]\n'
        '\n[[scenario]]\nname = "params"\ngiven.until = "1h"\nthen = ["alarms >= 0"]\n')
    project.makeconftest(
        "import dataclasses\n\n"
        "def pytest_collection_modifyitems(items):\n"
        "    for item in items:\n"
        "        if item.name == 'params':\n"
        "            item.scenario = dataclasses.replace(item.scenario,\n"
        "                                                params={'nonesuch': 3})\n")
    result = project.runpytest()
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines([_literal(
        "params.scenario.toml:7: scenario[1]: params: the spec has no package data field "
        "'nonesuch'*")])


def test_a_passing_run_does_not_read_the_file_for_lines(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from .conftest import DISPENSER

    # the module as imported now (pytester's inner runs may have replaced the package's)
    scenarios = importlib.import_module("opspec.testing.scenario")

    (tmp_path / "d.xpdl").write_bytes(DISPENSER.read_bytes())
    (tmp_path / "x.scenario.toml").write_text(
        'spec = "d.xpdl"\n[[scenario]]\nname = "a"\ngiven.until = "09:00"\n'
        'given.script = [["never", "press_report"]]\nthen = ["alarms == 3"]\n'
        '[[scenario]]\nname = "b"\ngiven.until = "09:00"\n'
        'given.script = [["never", "press_report"]]\nthen = ["alarms == 2"]\n')
    passing, failing = scenarios.load_scenarios(tmp_path / "x.scenario.toml").scenarios
    read: list[str] = []

    def located(path: str, key: str | None, text: str | None = None) -> object:
        read.append(str(key))
        return real(path, key, text)

    real = scenarios.located
    monkeypatch.setattr(scenarios, "located", located)
    assert scenarios.run_scenario(passing, DISPENSER) == []
    assert read == []
    assert scenarios.run_scenario(failing, DISPENSER)[0].startswith(
        f"{tmp_path / 'x.scenario.toml'}:11: scenario[1].then[0]: expected alarms == 2")
    assert read == ["scenario[1].then[0]"]


# ---------------------------------------------------------------- a script inside the file
def _collect_error(project: pytest.Pytester, text: str) -> str:
    (project.path / "bad.scenario.toml").write_text(text)
    result = project.runpytest()
    result.assert_outcomes(errors=1)
    return next(line for line in result.stdout.lines if line.startswith("bad scenario file"))


@pytest.mark.parametrize(("step", "message"), [
    ('["soon", "press_report"]', "cannot read the time 'soon'"),
    ('["10s"]', "a step is a (when, action) pair"),
    ('["10s", "dispense"]', "the script's step 'complete dispense' names activity 'dispense'"),
    ('["never", "report"]', "the script names activity 'report'"),
], ids=["unreadable-time", "not-a-pair", "device-activity", "unknown-activity"])
def test_an_inline_script_s_bad_step_is_placed_at_its_line(
        project: pytest.Pytester, step: str, message: str) -> None:
    said = _collect_error(project, (
        'spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\ngiven.script = [\n'
        f'  ["after trg_2 60s", "press_report"],\n  {step},\n]\nthen = ["alarms == 1"]\n'))
    assert said.startswith(
        f"bad scenario file: bad.scenario.toml:6: scenario[0].given.script[1]: {message}")


def test_a_step_of_the_file_s_given_script_is_placed_there(project: pytest.Pytester) -> None:
    # the script of [given] is every scenario's: its step is where it is written
    said = _collect_error(project, (
        'spec = "specs/dispenser.xpdl"\n[given]\nscript = [\n  ["never", "press_report"],\n'
        '  ["10s", "press_reprot"],\n]\n[[scenario]]\nname = "x"\nthen = ["alarms == 1"]\n'))
    assert said.startswith("bad scenario file: bad.scenario.toml:5: given.script[1]: the "
                           "script names activity 'press_reprot'")


def test_an_inline_script_that_is_no_list_is_placed_at_its_key(
        project: pytest.Pytester) -> None:
    said = _collect_error(project, (
        'spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n\n'
        'given.script = { never = "press_report" }\nthen = ["alarms == 1"]\n'))
    assert said.startswith("bad scenario file: bad.scenario.toml:5: scenario[0].given.script: "
                           "a script is a list of (when, action) pairs")


def test_a_script_file_names_the_line_of_the_scenario_that_uses_it(
        project: pytest.Pytester) -> None:
    # the script file given in [given]: the scenario's bracket names where it is given
    (project.path / "late.toml").write_text('steps = [\n  ["10s", "dispense"],\n]\n')
    said = _collect_error(project, (
        'spec = "specs/dispenser.xpdl"\n\n[given]\nscript = "late.toml"\n\n[[scenario]]\n'
        'name = "x"\nthen = ["alarms == 1"]\n'))
    assert said.startswith("bad scenario file: late.toml:2: steps[0]: the script's step")
    assert "(scenario 'x', bad.scenario.toml:4: given.script)" in said


def test_an_unknown_engine_option_is_placed_at_its_line(project: pytest.Pytester) -> None:
    said = _collect_error(project, (
        'spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "x"\n'
        'given.engine.speed = 60\ngiven.engine.timer_resolutoin = 1\n'
        'then = ["alarms == 1"]\n'))
    assert said.startswith("bad scenario file: bad.scenario.toml:5: "
                           "scenario[0].given.engine.timer_resolutoin: unknown engine option")


def test_the_error_raised_is_at_the_line_for_a_caller_of_load_scenarios(
        tmp_path: Path) -> None:
    from opspec.testing.scenario import load_scenarios

    from .conftest import DISPENSER

    (tmp_path / "d.xpdl").write_bytes(DISPENSER.read_bytes())
    (tmp_path / "x.scenario.toml").write_text(
        'spec = "d.xpdl"\n[[scenario]]\nname = "x"\ngiven.script = [\n'
        '  ["soon", "press_report"],\n]\nthen = ["alarms == 1"]\n')
    with pytest.raises(ConfigurationError) as raised:
        load_scenarios(tmp_path / "x.scenario.toml")
    at = raised.value.location
    assert (at.line, at.key) == (5, "scenario[0].given.script[0]")


def test_each_scenario_item_is_located_at_its_table(project: pytest.Pytester) -> None:
    """pytest places an item by ``reportinfo`` (its header in a failure, ``item.location``):
    a scenario is at the line of its ``[[scenario]]`` table, not at the top of the file."""
    (project.path / "specs" / "tests").mkdir()
    path = project.path / "specs" / "tests" / "pill.scenario.toml"
    path.write_text(FAILING)
    items, _ = project.inline_genitems(str(path))
    tables = [n for n, line in enumerate(FAILING.splitlines()) if line == "[[scenario]]"]
    assert [(item.name, item.location[1]) for item in items] == [
        ("prompt user", tables[0]), ("silent user", tables[1]), ("one line", tables[2])]
    assert all(item.location[2] == f"scenario: {item.name}" for item in items)
