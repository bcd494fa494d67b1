"""``--param NAME=VALUE`` for a process's formal parameter: run inputs set package data
fields only, and the refusal says that NAME is a formal parameter and what to change (it said
"the spec has no package data field", after validate's unpassed-parameter warning had said
--param would set the value once it is a package data field). The API's ``params`` and a
scenario file's ``given.params`` are the same door and say the same."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.cli import main
from opspec.errors import ConfigurationError

ROOT = Path(__file__).resolve().parents[2]
HEADER = """    <WorkflowProcess Id="user_workflow" Name="The user's manual workflow" AccessLevel="PUBLIC">
      <ProcessHeader/>
"""
FORMAL = """      <FormalParameters>
        <FormalParameter Id="pace" Mode="IN"><DataType><BasicType Type="INTEGER"/></DataType></FormalParameter>
      </FormalParameters>
"""


@pytest.fixture
def spec(tmp_path: Path) -> Path:
    text = (ROOT / "specs" / "medication_dispenser.xpdl").read_text(encoding="utf-8")
    assert HEADER in text
    path = tmp_path / "paced.xpdl"
    path.write_text(text.replace(HEADER, HEADER + FORMAL, 1), encoding="utf-8")
    return path


@pytest.mark.parametrize("how", ["param", "params"])
def test_a_value_for_a_formal_parameter_says_it_is_one(spec: Path, tmp_path: Path, capsys,
                                                       how: str) -> None:
    if how == "param":
        given = ["--param", "pace=2"]
    else:
        values = tmp_path / "values.toml"
        values.write_text("pace = 2\n", encoding="utf-8")
        given = ["--params", str(values)]
    assert main(["run", str(spec), "--days", "1", *given]) == 2
    said = capsys.readouterr().err.strip().splitlines()[-1]
    assert ("'pace' is a formal parameter of process 'user_workflow', not a package data "
            "field: run inputs set package data fields only") in said
    assert "declare it as a package data field instead of a formal parameter" in said
    assert "no package data field 'pace'" not in said


def test_a_name_that_is_nothing_is_refused_as_before(spec: Path, capsys) -> None:
    assert main(["run", str(spec), "--days", "1", "--param", "speed=2"]) == 2
    said = capsys.readouterr().err
    assert "the spec has no package data field 'speed'" in said


IS_ONE = ("'pace' is a formal parameter of process 'user_workflow', not a package data field: "
          "run inputs set package data fields only")


def test_the_api_s_params_say_the_same(spec: Path) -> None:
    with pytest.raises(ConfigurationError) as raised:
        opspec.run(spec, days=1, params={"pace": 2})
    assert str(raised.value).startswith("params: " + IS_ONE)
    assert "declare it as a package data field instead" in str(raised.value)


def test_a_scenario_file_s_given_params_say_the_same(spec: Path, tmp_path: Path) -> None:
    from opspec.testing.scenario import load_scenarios

    scenarios = tmp_path / "paced.scenario.toml"
    scenarios.write_text(f'spec = "{spec.name}"\n\n[[scenario]]\nname = "paced"\n'
                         'given.days = 1\ngiven.params.pace = 2\n'
                         'then = ["eventually activity take_pill done"]\n', encoding="utf-8")
    with pytest.raises(ConfigurationError) as raised:
        load_scenarios(scenarios)
    said = str(raised.value).removeprefix(str(scenarios))
    assert said.startswith(":6: scenario[0].given.params.pace: " + IS_ONE), said
