"""A newcomer's slips in a user model, found at the line they are on (``file:line: key``),
each saying what to do: a misspelt activity in ``[busy]``, a forgotten duration, a top-level
key appended below the last table, an error in the second of several windows, a typo'd
activity table, an error in the base model a file extends."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import UserModelError
from opspec.usermodels import load_user_model

ROOT = Path(__file__).resolve().parents[2]
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
MANUAL = ["hear_alarm", "walk_to_dispenser", "press_report", "press_wrong_button", "take_pill"]
CHOICES = {"choose_button": ["press_report", "press_wrong_button"]}


def _write(tmp_path: Path, text: str, name: str = "users.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _line_of(text: str, written: str) -> int:
    (line,) = [n for n, row in enumerate(text.splitlines(), start=1) if written in row]
    return line


def _shipped(tmp_path: Path, old: str, new: str) -> tuple[Path, str]:
    text = USERS.read_text(encoding="utf-8")
    assert old in text
    text = text.replace(old, new, 1)
    return _write(tmp_path, text), text


@pytest.mark.parametrize("key", ["ignore", "release_after"])
def test_a_misspelt_activity_in_busy_is_warned_at_its_line(tmp_path: Path, key: str) -> None:
    # busy.engaged was checked; an ignore or release_after id the spec lacks never matched,
    # without a word
    path, text = _shipped(tmp_path, 'ignore = ["hear_alarm"]',
                          f'{key} = ["hear_alrm"]')
    warnings = load_user_model(path).validate_against(MANUAL, choices=CHOICES)
    assert [str(w) for w in warnings] == [(
        f"{path}:{_line_of(text, 'hear_alrm')}: busy.{key}: warning: busy.{key} names "
        "'hear_alrm', which the spec's user lane lacks (check the spelling against the "
        "spec's activity ids)")]


def test_a_manual_activity_without_a_duration_is_warned(tmp_path: Path) -> None:
    # a forgotten (or misspelt: "duraton" is refused) duration line made take_pill take no
    # time without a word
    path, text = _shipped(
        tmp_path, '[activities.take_pill]\nduration = { kind = "lognormal", median = 20.0, '
        'sigma = 0.4 }\n', "[activities.take_pill]\n")
    warnings = load_user_model(path).validate_against(MANUAL, choices=CHOICES)
    assert [(w.code, w.location.line, w.location.key) for w in warnings] == [
        ("no-duration", _line_of(text, "[activities.take_pill]"), "activities.take_pill")]
    assert warnings[0].message == ("activity 'take_pill' has no duration in "
                                   "[activities.take_pill], so it takes no time")
    assert warnings[0].hint.startswith("write duration = 0.0 in [activities.take_pill] if it "
                                       "takes no time, or a distribution")


def test_noticing_a_prompt_and_a_choices_alternative_need_no_duration(tmp_path: Path) -> None:
    path, _ = _shipped(tmp_path, "duration = 0.0\nomission", "omission")          # hear_alarm
    text = path.read_text(encoding="utf-8").replace("duration = 10.0\n", "", 1)  # an alternative
    path.write_text(text, encoding="utf-8")
    assert load_user_model(path).validate_against(MANUAL, choices=CHOICES) == []


def test_a_top_level_key_appended_below_the_last_table_says_where_it_belongs(
        tmp_path: Path) -> None:
    path, text = _shipped(tmp_path, 'name = "medication-dispenser-user"\n', "")
    text += 'name = "medication-dispenser-user"\n'
    path.write_text(text, encoding="utf-8")
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value).startswith(
        f"{path}:{len(text.splitlines())}: activities.take_pill.name: unknown key")
    assert refused.value.hint.endswith(
        "name belongs at the top of the file: a key written below a [table] line is in that "
        "table, so move it above the first [table] line")


def test_an_error_in_the_second_window_is_at_its_line(tmp_path: Path) -> None:
    text = ('[[routine.windows]]\nname = "asleep"\nstart = "23:00"\nend = "07:00"\n\n'
            '[[routine.windows]]\nname = "out"\nstart = "14:00"\nend = "31:00"\n')
    path = _write(tmp_path, text)
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value).startswith(f"{path}:9: routine.windows[1].end: ")


def test_an_uncovered_activity_is_refused_at_the_table_that_is_likely_its_typo(
        tmp_path: Path) -> None:
    path, text = _shipped(tmp_path, "[activities.take_pill]", "[activities.take_pil]")
    with pytest.raises(UserModelError) as refused:
        load_user_model(path).validate_against(MANUAL, choices=CHOICES)
    assert str(refused.value).startswith(
        f"{path}:{_line_of(text, '[activities.take_pil]')}: activities.take_pil: user model "
        "'medication-dispenser-user' does not cover manual activity of the spec: take_pill; "
        "[activities.take_pil] is not an activity of the spec: did you mean take_pill?")


def test_a_warning_names_the_line_of_its_table(tmp_path: Path) -> None:
    text = USERS.read_text(encoding="utf-8") + "\n[activities.dance]\nduration = 3\n"
    path = _write(tmp_path, text)
    (warning,) = load_user_model(path).validate_against(MANUAL, choices=CHOICES)
    assert str(warning).startswith(
        f"{path}:{_line_of(text, '[activities.dance]')}: activities.dance: warning: ")


def test_an_error_in_the_base_model_is_at_the_base_files_line(tmp_path: Path) -> None:
    _write(tmp_path, '# the base\n[activities.walk]\nduration = { kind = "lognormal", '
           'median = 60, sigma = -1 }\n', "base.toml")
    path = _write(tmp_path, 'extends = "base.toml"\n')
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value).startswith(
        f"{tmp_path / 'base.toml'}:3: activities.walk.duration.sigma: must be > 0")


def test_the_second_correlation_of_a_population_is_at_its_line(tmp_path: Path) -> None:
    _write(tmp_path, USERS.read_text(encoding="utf-8"), USERS.name)
    text = (f'extends = "{USERS.name}"\n'
            "[vary.activities.hear_alarm.omission]\n"
            'probability = { kind = "beta", mean = 0.15, sd = 0.08 }\n'
            "[vary.activities.walk_to_dispenser.duration]\n"
            'median = { kind = "lognormal", median = 60.0, sigma = 0.25 }\n'
            "[[correlations]]\n"
            'parameters = ["activities.hear_alarm.omission.probability", '
            '"activities.walk_to_dispenser.duration.median"]\n'
            "spearman = 0.3\n"
            "[[correlations]]\n"
            'parameters = ["activities.hear_alarm.omission.probability", '
            '"activities.walk_to_dispenser.duration.median"]\n'
            "spearman = 1.3\n")
    path = _write(tmp_path, text, "people.toml")
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value).startswith(f"{path}:11: correlations[1].spearman: ")


@pytest.mark.parametrize(("ref", "says"), [
    ("nope.toml", "extends 'nope.toml': user model file not found"),
    ("older-adult", ("extends 'older-adult': no user model file or preset called "
                     "'older-adult'; did you mean 'older-adults'?")),
])
def test_a_base_that_does_not_exist_is_refused_at_the_extends_line(
        tmp_path: Path, ref: str, says: str) -> None:
    # it said "nope.toml: user model file not found", naming neither this file nor its line
    path = _write(tmp_path, f'name = "mine"\nextends = "{ref}"\n')
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value).startswith(f"{path}:2: extends: {says}")


def test_a_description_that_is_not_text_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, 'name = "mine"\ndescription = 3\n')
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value) == f"{path}:2: description: must be a string, got 3"


def test_a_byte_order_mark_in_front_is_no_syntax_error(tmp_path: Path) -> None:
    # Windows editors save UTF-8 with a BOM; tomllib called it an "Invalid statement" at line 1
    path = tmp_path / "users.toml"
    path.write_text('\ufeffname = "mine"\n[activities.walk]\nduration = { kind = "gamma", '
                    'shape = -1, scale = 1 }\n', encoding="utf-8")
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value).startswith(f"{path}:3: activities.walk.duration.shape: ")
    path.write_text('\ufeffname = "mine"\n', encoding="utf-8")
    assert load_user_model(path).name == "mine"


def test_a_subgroup_without_a_share_is_told_it_needs_one(tmp_path: Path) -> None:
    # it said "must be a share in (0, 1], got None"
    _write(tmp_path, USERS.read_text(encoding="utf-8"), USERS.name)
    path = _write(tmp_path, f'extends = "{USERS.name}"\n[subgroups.a]\ndescription = "x"\n',
                  "people.toml")
    with pytest.raises(UserModelError) as refused:
        load_user_model(path)
    assert str(refused.value) == (f"{path}:2: subgroups.a.share: is required: the share of the "
                                  "users in this subgroup (write a fraction: 70 % is "
                                  "share = 0.7)")
