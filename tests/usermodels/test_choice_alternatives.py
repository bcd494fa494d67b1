"""A deferred choice on the real engine: the time a pick takes (the chosen alternative's own
duration, e.g. "pressing the wrong button first costs 10 s") is simulated; alternatives need no
model of their own; models that leave a choice to chance, or name activities the spec lacks,
are reported on stderr."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.engine.lanes import user_lane
from opspec.testing.simulation import simulate
from opspec.usermodels.loader import load_user_model
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"

MODEL = """
format = "opspec-user-model"
name = "always-wrong-first"
[busy]
engaged = ["walk_to_dispenser", "choose_button"]
ignore = ["hear_alarm"]
[activities.hear_alarm]
duration = 0.0
[activities.walk_to_dispenser]
duration = 60.0
[activities.choose_button]
duration = 0.0
intended = "press_report"
commission = {{ probability = 1.0, alternatives = ["press_wrong_button"], max_per_instance = 1 }}
{wrong}
[activities.take_pill]
duration = 20.0
"""


def model_file(tmp_path: Path, wrong: str) -> Path:
    path = tmp_path / "user.toml"
    path.write_text(MODEL.format(wrong=wrong), encoding="utf-8")
    return path


@pytest.mark.parametrize("wrong, latency", [
    ("[activities.press_wrong_button]\nduration = 100.0", 160.0),
    ("[activities.press_wrong_button]\nduration = 10.0", 70.0),
    ("", 60.0),                      # no model of the alternative: the pick itself is instant
], ids=["wrong-button-100s", "wrong-button-10s", "alternative-not-modelled"])
def test_the_time_a_wrong_pick_takes_delays_the_report(wrong, latency, tmp_path):
    result = simulate(SPEC, users=3, until=9 * 3600, user_model=model_file(tmp_path, wrong))
    assert result.metrics["doses_taken"]["total"] == 3
    assert result.samples("report_latency_s") == pytest.approx([latency] * 3)


def test_alternatives_of_a_choice_are_not_offered_so_need_no_model():
    lane = user_lane(compile_package(open_spec(SPEC)))
    assert lane.manual == ("hear_alarm", "walk_to_dispenser", "take_pill")
    assert lane.choices == {"choose_button": ("press_report", "press_wrong_button")}


def test_the_reference_model_has_no_warnings_against_its_spec():
    lane = user_lane(compile_package(open_spec(SPEC)))
    model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
    assert model.validate_against(lane.manual, choices=lane.choices) == []


def test_run_warns_about_a_misspelt_activity_and_a_choice_left_to_chance(tmp_path, capsys):
    path = tmp_path / "typo.toml"
    path.write_text(MODEL.format(wrong="").replace("take_pill", "take_pil").replace(
        'intended = "press_report"\n', "").replace("commission = {", "# {"), encoding="utf-8")
    path.write_text(path.read_text(encoding="utf-8") + "[defaults]\nduration = 1.0\n",
                    encoding="utf-8")
    status = main(["run", str(SPEC), "--until", "3600", "--user-model", str(path),
                   "--timeline", "none"])
    err = capsys.readouterr().err
    assert status == 0
    line = path.read_text(encoding="utf-8").splitlines().index("[activities.take_pil]") + 1
    assert (f"{path}:{line}: activities.take_pil: warning: activity 'take_pil' is not a "
            "manual ") in err
    assert "choice 'choose_button': the model names no intended alternative" in err
