"""A script's mistakes (opspec.usermodels.scripts) are placed where they are written: a TOML
script file's at ``file:line: steps[N]`` (each entry of the multi-line ``steps`` array at its
own line, a step table too), its other keys at theirs; a step naming an activity or trigger
the spec lacks is placed at that step and suggests the closest names before listing every
one (the list of some thirty names was all it said)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import opspec
from opspec.cli import main
from opspec.errors import ConfigurationError
from opspec.usermodels.scripts import load_script, parse_script

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"

SCRIPT = """# a late user
otherwise = "complete"
steps = [
  ["after trg_2 90s", "press_report"],
  { when = "each 30s", do = "take_pill" },
  ["10s", "{step}"],
]
"""


def _script(tmp_path: Path, step: str) -> Path:
    path = tmp_path / "late.toml"
    path.write_text(SCRIPT.replace("{step}", step), encoding="utf-8")
    return path


def _refusal(call) -> str:   # type: ignore[no-untyped-def]
    with pytest.raises(ConfigurationError) as refused:
        call()
    return str(refused.value)


def test_a_misspelt_activity_suggests_the_closest_first(tmp_path: Path) -> None:
    said = _refusal(lambda: opspec.run(DISPENSER, script=_script(tmp_path, "take_pil")))
    assert said.startswith(
        f"{tmp_path / 'late.toml'}:6: steps[2]: the script names activity 'take_pil', which "
        "the spec does not have (did you mean 'take_pill'?) (known activities: ")
    assert said.index("did you mean") < said.index("known activities")


def test_a_misspelt_trigger_and_anchor_suggest_theirs() -> None:
    said = _refusal(lambda: opspec.run(DISPENSER, script=[("at 1", "raise trg_3")]))
    assert "<script>: steps[0]: the script names trigger 'trg_3'" in said
    assert "(did you mean 'trg_2' or 'trg_1'?) (known triggers: trg_1, trg_2)" in said
    said = _refusal(lambda: opspec.run(DISPENSER, script=[(1, "hear_alarm"),
                                                           ("after trg_22 5s", "take_pill")]))
    assert said.startswith("<script>: steps[1]: the script names anchor 'trg_22', which the "
                           "spec does not have (did you mean 'trg_2'")


def test_a_name_close_to_nothing_lists_the_names_alone(tmp_path: Path) -> None:
    said = _refusal(lambda: opspec.run(DISPENSER, script=_script(tmp_path, "xyzzy")))
    assert "'xyzzy', which the spec does not have (known activities: " in said
    assert "did you mean" not in said


def test_run_says_it_at_the_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _script(tmp_path, "press_reprot")
    assert main(["run", str(DISPENSER), "--script", str(path), "--until", "1h"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"opspec run: {path}:6: steps[2]: the script names activity "
                          "'press_reprot', which the spec does not have (did you mean "
                          "'press_report'")


def test_a_step_on_a_device_activity_is_placed_at_its_line(tmp_path: Path) -> None:
    said = _refusal(lambda: opspec.run(DISPENSER, script=_script(tmp_path, "dispense")))
    assert said.startswith(f"{tmp_path / 'late.toml'}:6: steps[2]: the script's step "
                           "'complete dispense' names activity 'dispense', which is never "
                           "offered to the user")


@pytest.mark.parametrize(("step", "line", "says"), [
    ('["soon", "take_pill"]', 6, "steps[2]: cannot read the time 'soon'"),
    ('{ do = "take_pill", after = 3 }', 6, "steps[2]: a step table has 'do'"),
    ('["1s"]', 6, "steps[2]: a step is a (when, action) pair"),
    ('["never", "omit take_pill"]', 6, "steps[2]: 'never' takes one activity name"),
], ids=["bad-time", "table-key", "short-pair", "never-verb"])
def test_a_bad_step_is_at_its_line(tmp_path: Path, step: str, line: int, says: str) -> None:
    path = tmp_path / "late.toml"
    path.write_text(SCRIPT.replace('["10s", "{step}"]', step), encoding="utf-8")
    assert _refusal(lambda: load_script(path)).startswith(f"{path}:{line}: {says}")


def test_the_files_other_keys_are_at_their_lines(tmp_path: Path) -> None:
    path = tmp_path / "late.toml"
    path.write_text(SCRIPT.replace("{step}", "take_pill").replace(
        'otherwise = "complete"', 'otherwise = "later"'), encoding="utf-8")
    assert _refusal(lambda: load_script(path)).startswith(f"{path}:2: otherwise: ")
    path.write_text(SCRIPT.replace("{step}", "take_pill") + "speed = 2\n", encoding="utf-8")
    assert _refusal(lambda: load_script(path)).startswith(f"{path}:8: speed: unknown key")


def test_a_json_script_keeps_its_keys(tmp_path: Path) -> None:
    path = tmp_path / "late.json"
    path.write_text(json.dumps({"steps": [[1, "hear_alarm"], ["soon", "take_pill"]]}),
                    encoding="utf-8")
    assert _refusal(lambda: load_script(path)).startswith(
        f"{path}: steps[1]: cannot read the time 'soon'")


def test_a_script_in_python_keeps_its_form() -> None:
    assert _refusal(lambda: parse_script([(1, "hear_alarm"), ("soon", "x")])).startswith(
        "<script>: steps[1]: cannot read the time 'soon'")
