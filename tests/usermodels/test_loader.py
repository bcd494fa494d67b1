"""User-model TOML: loading, precise errors, presets with provenance, round trip."""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest

from opspec.errors import Severity, UserModelError
from opspec.usermodels import (
    dump_user_model,
    load_user_model,
    parse_user_model,
    preset_names,
    resolve_preset,
)
from opspec.usermodels.distributions import Constant, WithExponentialTail

DISPENSER_MANUAL = ["hear_alarm", "walk_to_dispenser", "press_report", "press_wrong_button",
                    "take_pill"]
DISPENSER_CHOICES = {"choose_button": ["press_report", "press_wrong_button"]}

GOOD = '''
name = "users"
[activities.hear_alarm]
omission = 0.15
source = "test"
[activities.walk_to_dispenser]
duration = { kind = "lognormal", median = 60, sigma = 0.6 }
'''


def write(tmp_path: Path, text: str, name: str = "users.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_the_dispenser_user_model_has_the_reference_parameters(dispenser_users_path) -> None:
    model = load_user_model(dispenser_users_path)
    assert model.activities["hear_alarm"].omission.probability == 0.15
    walk = model.activities["walk_to_dispenser"].duration
    assert walk.quantile(0.5) == pytest.approx(60.0) and walk.sigma == 0.6
    pill = model.activities["take_pill"].duration
    assert pill.quantile(0.5) == pytest.approx(20.0) and pill.sigma == 0.4
    choose = model.activities["choose_button"]
    assert choose.intended == "press_report" and choose.commission.probability == 0.05
    assert model.activities["press_wrong_button"].duration == Constant(10.0)
    assert model.busy is not None and "walk_to_dispenser" in model.busy.engaged
    assert model.validate_against(DISPENSER_MANUAL, choices=DISPENSER_CHOICES) == []


def test_the_dispenser_preset_equals_the_spec_user_model(dispenser_users_path) -> None:
    spec = load_user_model(dispenser_users_path)
    preset = load_user_model("dispenser-reference")
    assert dict(spec.activities) == dict(preset.activities) and spec.busy == preset.busy


BAD = {
    "negative-sigma": (('[activities.walk_to_dispenser]\n'
                       'duration = { kind = "lognormal", median = 60, sigma = -1 }'),
                       (r"users.toml:2: activities.walk_to_dispenser.duration.sigma: "
                       r"must be > 0, got -1")),
    "unknown-distribution": ('[activities.walk]\nduration = { kind = "gauss", mean = 1 }',
                             (r"users.toml:2: activities.walk.duration.kind: unknown "
                             r"distribution 'gauss' \(use one of: constant")),
    "probability-above-1": ('[activities.hear]\nomission = 1.5',
                            (r"users.toml:2: activities.hear.omission.probability: must be a "
                            r"probability in \[0, 1\], got 1.5")),
    "negative-probability": (('[activities.c]\nintended = "a"\n'
                             'commission = { probability = -0.1 }'),
                             r"users.toml:3: activities.c.commission.probability: must be a probability"),
    "unknown-activity-key": ('[activities.walk]\nduraton = 3',
                             (r"users.toml:2: activities.walk.duraton: unknown key \(expected "
                             r"one of: duration")),
    "unknown-top-key": ('[activites.walk]\nduration = 3', r"users.toml:1: activites: unknown key"),
    "bad-window": ('[[routine.windows]]\nname = "asleep"\nstart = "23:00"\nend = "31:00"',
                   r"users.toml:4: routine.windows\[0\].end: cannot read time of day '31:00'"),
    "busy-string": ('[busy]\nengaged = "walk"', r"users.toml:2: busy.engaged: must be a list"),
    "probabilities-sum": ('[activities.c]\nprobabilities = { a = 0.5, b = 0.6 }',
                          r"users.toml:2: activities.c.probabilities: must add up to 1, got 1.1"),
    "bad-version": ('version = 7', r"users.toml:1: version: unsupported version 7"),
    "nested-typo": (('[activities.w]\nduration = { kind = "with_tail", tau = 1, '
                    'base = { kind = "gamma", shape = -1, scale = 1 } }'),
                    r"users.toml:2: activities.w.duration.base.shape: must be > 0"),
    "not-toml": ('[activities.walk\n', r"users.toml:1: not valid TOML"),
}


@pytest.mark.parametrize(("text", "message"), BAD.values(), ids=BAD.keys())
def test_invalid_files_name_the_file_line_and_dotted_key(tmp_path: Path, text: str,
                                                    message: str) -> None:
    with pytest.raises(UserModelError, match=message):
        load_user_model(write(tmp_path, text))


def test_a_missing_file_says_so_and_lists_presets(tmp_path: Path) -> None:
    with pytest.raises(UserModelError, match=r"nope.toml: user model file not found.*"
                       r"dispenser-reference"):
        load_user_model(str(tmp_path / "nope.toml"))


def test_an_unknown_preset_lists_the_presets() -> None:
    with pytest.raises(UserModelError, match=r"no user model file or preset called 'young'.*"
                       r"older-adults"):
        load_user_model("young")


@pytest.mark.parametrize(("typo", "meant"), [("older-adlts", "older-adults"),
                                             ("olderadults", "older-adults"),
                                             ("dispenser-referance", "dispenser-reference")])
def test_a_misspelt_preset_gets_the_closest_one_and_the_list(typo: str, meant: str) -> None:
    with pytest.raises(UserModelError) as refused:
        load_user_model(typo)
    said = str(refused.value)
    assert f"no user model file or preset called {typo!r}; did you mean {meant!r}?" in said
    assert "klm" in said                  # and every preset, as before


def test_a_name_near_no_preset_gets_no_guess() -> None:
    with pytest.raises(UserModelError) as refused:
        load_user_model("zzzz")
    assert "did you mean" not in str(refused.value)


def test_uncovered_manual_activities_name_the_file_the_ids_and_the_fix(tmp_path: Path) -> None:
    model = load_user_model(write(tmp_path, GOOD))
    with pytest.raises(UserModelError, match=r"users.toml:3: activities: user model 'users' does "
                       r"not cover manual activities of the spec: press_report, take_pill "
                       r"\(add \[activities.press_report\] \[activities.take_pill\]"):
        model.validate_against(["hear_alarm", "walk_to_dispenser", "press_report", "take_pill"])


def test_an_uncovered_activity_names_the_table_that_is_likely_its_typo(tmp_path: Path
                                                                      ) -> None:
    model = load_user_model(write(tmp_path, GOOD + '[activities.take_pil]\n'
                                  'duration = { kind = "constant", value = 5 }\n'))
    with pytest.raises(UserModelError, match=r"spec: take_pill; \[activities.take_pil\] is "
                       r"not an activity of the spec: did you mean take_pill\?"):
        model.validate_against(["hear_alarm", "walk_to_dispenser", "take_pill"])


def test_a_choice_naming_an_alternative_the_spec_lacks_is_an_error(tmp_path: Path) -> None:
    model = load_user_model(write(tmp_path, GOOD + '[activities.c]\nintended = "press_reprot"\n'))
    with pytest.raises(UserModelError, match=r"choice 'c' has no alternative 'press_reprot' "
                       r"\(the spec offers: press_report"):
        model.validate_against(["hear_alarm", "walk_to_dispenser"],
                               choices={"c": ["press_report", "x"]})


def test_activities_the_spec_lacks_are_warnings(tmp_path: Path) -> None:
    model = load_user_model(write(tmp_path, GOOD))
    warnings = model.validate_against(["hear_alarm"])
    assert [w.severity for w in warnings] == [Severity.WARNING]
    assert "walk_to_dispenser" in warnings[0].message


def test_defaults_cover_every_activity(tmp_path: Path) -> None:
    model = load_user_model(write(tmp_path, GOOD + '[defaults]\nduration = 2\n'))
    assert model.validate_against(["anything"]) == [
        w for w in model.validate_against(["anything"])]
    assert model.activity("anything").duration == Constant(2.0)


def test_a_modifier_preset_alone_covers_nothing() -> None:
    with pytest.raises(UserModelError, match=r"older-adults.toml: 'older-adults' is a modifier "
                       r".*combine it with a base model, e.g. --user-model "
                       r"SPEC.users.toml,older-adults"):
        load_user_model("older-adults").validate_against(["walk"])


def test_presets_compose_with_a_comma(dispenser_users_path) -> None:
    model = load_user_model(f"{dispenser_users_path},older-adults,mci")
    walk = model.activities["walk_to_dispenser"].duration
    assert isinstance(walk, WithExponentialTail)
    assert walk.base.quantile(0.5) == pytest.approx(60 * 1.5 * 1.1)
    assert walk.tau == pytest.approx(0.5 * walk.base.mean)
    assert model.activities["hear_alarm"].omission.probability == pytest.approx(1 - 0.85 * 0.9)
    assert model.name == "medication-dispenser-user+older-adults+mci"


def test_a_file_can_extend_a_preset_and_override_an_activity(tmp_path: Path) -> None:
    model = load_user_model(write(tmp_path, 'extends = "dispenser-reference"\n'
                                  '[activities.take_pill]\nduration = 5\n'))
    assert model.activities["take_pill"].duration == Constant(5.0)
    assert model.activities["walk_to_dispenser"].duration.sigma == 0.6


def test_a_file_that_extends_another_and_names_itself_is_called_so(tmp_path: Path) -> None:
    # the bundled population extends the reference user: its report said "User model
    # medication-dispenser-user (…population.toml)", not the name the file gives
    shipped = Path(__file__).resolve().parents[2] / "specs"
    assert load_user_model(shipped / "medication_dispenser.population.toml").name == (
        "dispenser-population")
    named = write(tmp_path, 'name = "careful"\nextends = "dispenser-reference"\n'
                  '[activities.take_pill]\nduration = 5\n')
    assert load_user_model(named).name == "careful"
    # unnamed, it is its base with what it changes; composed with a comma, the same
    unnamed = write(tmp_path, 'extends = "dispenser-reference"\n[activities.take_pill]\n'
                    'duration = 5\n', "faster.users.toml")
    assert load_user_model(unnamed).name == "dispenser-reference+faster"


def test_klm_operators_add_up() -> None:
    model = load_user_model("klm")
    assert model.activity("press_report").duration.mean == pytest.approx(1.35 + 0.28)


def test_klm_operators_can_be_used_in_any_file(tmp_path: Path) -> None:
    model = load_user_model(write(tmp_path, '[activities.type_code]\n'
                                  'duration = { kind = "klm", operators = "M K K K K" }\n'))
    assert model.activities["type_code"].duration.mean == pytest.approx(1.35 + 4 * 0.28)
    with pytest.raises(UserModelError, match=r"operators: unknown KLM operator 'Q'"):
        load_user_model(write(tmp_path, '[activities.a]\n'
                              'duration = { kind = "klm", operators = "M Q" }\n'))


FULL = '''
name = "everything"
description = "every feature"
source = "tests"
[defaults]
duration = { kind = "gamma", shape = 2, scale = 1.5 }
[busy]
engaged = ["walk"]
release_after = ["walk"]
[routine]
[[routine.windows]]
name = "asleep"
start = "23:00"
end = "07:00"
notice_factor = 0.25
[[routine.windows]]
name = "out"
start = "14:00"
end = "16:30"
defer = true
probability = 0.3
[routine.drift]
notice_factor_per_day = 0.995
min_notice_factor = 0.6
duration_factor_per_day = 0.99
min_duration_factor = 0.8
[activities.walk]
duration = { kind = "empirical", values = [50, 61.5, 70], jitter = 2 }
repetition = 0.01
delay = { probability = 0.1, duration = { kind = "exponential", mean = 30 } }
commission = { probability = 0.02, recovery = { kind = "uniform", low = 1, high = 4 } }
[activities.c]
probabilities = { a = 0.25, b = 0.75 }
[activities.hear]
omission = { probability = 0.1, reason = "not heard" }
prompt = true
'''


@pytest.mark.parametrize("name", ["everything", "dispenser-reference", "klm", "mci+base"])
def test_dump_reads_back_to_an_equal_model(tmp_path: Path, name: str) -> None:
    if name == "everything":
        model = load_user_model(write(tmp_path, FULL))
    elif name == "mci+base":
        model = load_user_model("dispenser-reference,older-adults,mci")
    else:
        model = load_user_model(name)
    again = parse_user_model(tomllib.loads(dump_user_model(model)), "again.toml")
    assert dict(again.activities) == dict(model.activities)
    assert again.default == model.default
    assert again.busy == model.busy
    assert again.routine == model.routine


def _tables_missing_source(doc: Mapping[str, Any], key: str, inherited: bool) -> list[str]:
    missing = []
    has = inherited or "source" in doc
    numbers = [k for k, v in doc.items() if isinstance(v, (int, float)) and not
               isinstance(v, bool) and k not in ("version",)]
    if numbers and not has:
        missing.append(key)
    for k, v in doc.items():
        if isinstance(v, Mapping) and k not in ("duration",):
            missing += _tables_missing_source(v, f"{key}.{k}", has)
        elif isinstance(v, list):
            for i, entry in enumerate(v):
                if isinstance(entry, Mapping):
                    missing += _tables_missing_source(entry, f"{key}.{k}[{i}]", has)
    return missing


@pytest.mark.parametrize("name", preset_names())
def test_every_number_in_a_preset_has_a_source(name: str) -> None:
    doc = tomllib.loads(resolve_preset(name).read_text(encoding="utf-8"))
    assert doc.get("source")
    # Below the top level, every table holding numbers carries (or inherits) its own source.
    missing = []
    for key, value in doc.items():
        if isinstance(value, Mapping):
            for sub, table in value.items():
                if isinstance(table, Mapping):
                    missing += _tables_missing_source(table, f"{key}.{sub}", False)
                elif isinstance(table, (int, float)) and "source" not in value:
                    missing.append(f"{key}.{sub}")
    assert missing == []


def test_the_presets_are_bundled() -> None:
    assert {"klm", "older-adults", "mci", "dispenser-reference"} <= set(preset_names())
