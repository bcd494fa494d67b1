"""``opspec validate SPEC`` checks the files ``opspec run SPEC`` picks up beside the spec, as
the run checks them (validate = run): the companion ``SPEC.users.toml``, read and checked
against the spec's user lane, each problem in the run's words at its file and key, in the
counts, the exit status and ``--json``; the summary names the files it checked; an absent one
is no problem; with a broken spec the user model is still read. The shipped specs validate
clean with theirs."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.request import RunRequest, prepare, side_files

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"
MODEL = (SPECS / "medication_dispenser.users.toml").read_text(encoding="utf-8")


def make_spec(folder: Path, model: str | None = MODEL) -> Path:
    """pill.xpdl (the dispenser) in ``folder``, with ``model`` as pill.users.toml."""
    spec = folder / "pill.xpdl"
    shutil.copyfile(SPECS / "medication_dispenser.xpdl", spec)
    if model is not None:
        (folder / "pill.users.toml").write_text(model, encoding="utf-8")
    return spec


def _line_of(written: str) -> int:
    """The line of the shipped user model holding ``written`` (the first)."""
    return next(n for n, line in enumerate(MODEL.splitlines(), start=1) if written in line)


def validate(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, list[str]]:
    status = main(["validate", *argv])
    return status, capsys.readouterr().out.splitlines()


def run_refusal(capsys: pytest.CaptureFixture[str], spec: Path) -> str:
    """What ``opspec run SPEC`` says when it refuses the spec's side file (exit 2)."""
    assert main(["run", str(spec), "--days", "0.01"]) == 2
    said = capsys.readouterr().err.strip()
    assert said.startswith("opspec run: "), said
    return said.removeprefix("opspec run: ")


# a typo in the user model: what to write in place of what (the same file run picks up)
BROKEN = {
    "negative-probability": ("probability = 0.15", "probability = -0.15"),
    "unknown-key": ('source = "SCENARIO.md: hearing', 'sorce = "SCENARIO.md: hearing'),
    "activity-the-spec-lacks": ("[activities.take_pill]", "[activities.take_pil]"),
    "unknown-distribution": ('kind = "lognormal", median = 60.0',
                             'kind = "gauss", median = 60.0'),
}


def test_a_clean_user_model_beside_the_spec_is_named_in_the_summary(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = make_spec(tmp_path)
    assert validate(capsys, str(spec)) == (
        0, ["1 file checked with pill.users.toml beside it: no errors (0 errors, 0 warnings)"])


@pytest.mark.parametrize("typo", list(BROKEN))
def test_a_user_model_run_refuses_is_an_error_in_the_runs_words(
        typo: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    old, new = BROKEN[typo]
    assert old in MODEL
    spec = make_spec(tmp_path, MODEL.replace(old, new, 1))
    refused = run_refusal(capsys, spec)
    status, out = validate(capsys, str(spec))
    assert status == 1
    # path:line: key: error: message (hint), where run says path:line: key: message (hint);
    # the line is the one the typo is on (an editor jumps to it)
    problems = [line for line in out if ": error: " in line]
    assert [p.replace(": error: ", ": ", 1) for p in problems] == [refused]
    assert problems[0].startswith(f"{tmp_path / 'pill.users.toml'}:{_line_of(old)}: ")
    assert out[-1] == ("1 file checked with pill.users.toml beside it: 1 with errors "
                       "(1 error, 0 warnings)")


def test_a_toml_syntax_error_is_placed_at_its_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lines = MODEL.splitlines()
    broken = next(n for n, line in enumerate(lines) if line.startswith("duration = 10.0"))
    lines[broken] = "duration = "
    spec = make_spec(tmp_path, "\n".join(lines) + "\n")
    refused = run_refusal(capsys, spec)
    status, out = validate(capsys, str(spec))
    assert status == 1
    model = tmp_path / "pill.users.toml"
    # run names the line in its message; validate also puts it where editors look for it
    assert f"(at line {broken + 1}, column" in refused
    assert refused.startswith(f"{model}:{broken + 1}: not valid TOML: ")
    assert out[0] == f"{model}:{broken + 1}: error: " + refused.removeprefix(
        f"{model}:{broken + 1}: ")


def test_the_runs_warnings_on_the_user_model_are_validates_warnings(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = make_spec(tmp_path, MODEL + "\n[activities.tkae_pill]\nduration = 3.0\n")
    warned = [str(w) for w in prepare(RunRequest(str(spec))).warnings]
    status, out = validate(capsys, str(spec))
    assert status == 0
    assert out[:-1] == warned and len(warned) == 1
    assert ": activities.tkae_pill: warning: " in warned[0]
    assert out[-1] == ("1 file checked with pill.users.toml beside it: no errors "
                       "(0 errors, 1 warning)")
    # --strict: every warning an error, the side file's too
    status, out = validate(capsys, "--strict", str(spec))
    assert status == 1
    assert ": activities.tkae_pill: error: " in out[0]


def test_an_absent_user_model_is_no_problem(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    spec = make_spec(tmp_path, None)
    assert side_files(spec) == {}
    assert validate(capsys, str(spec)) == (
        0, ["1 file checked: no errors (0 errors, 0 warnings)"])
    status, out = validate(capsys, "--json", str(spec))
    assert status == 0
    assert json.loads(out[0])["side_files"] == []


def test_a_folder_named_like_the_user_model_is_not_picked_up(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = make_spec(tmp_path, None)
    (tmp_path / "pill.users.toml").mkdir()          # run does not read it either
    assert validate(capsys, str(spec))[0] == 0


def test_json_reports_the_side_files_problem_with_its_key(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = make_spec(tmp_path, MODEL.replace("probability = 0.15", "probability = -0.15", 1))
    status, out = validate(capsys, "--json", str(spec))
    assert status == 1
    (doc,) = [json.loads(line) for line in out]
    assert doc["ok"] is False
    (problem,) = doc["diagnostics"]
    assert problem == {
        "path": str(tmp_path / "pill.users.toml"), "line": _line_of("probability = 0.15"),
        "severity": "error",
        "code": "bad-user-model", "message": "must be a probability in [0, 1], got -0.15",
        "hint": "write a fraction: 15 % is 0.15",
        "key": "activities.hear_alarm.omission.probability"}
    assert doc["side_files"] == [{"path": str(tmp_path / "pill.users.toml"),
                                  "what": "user model", "checked": True, "why_not": None,
                                  "given": False}]


def test_a_broken_spec_still_has_its_user_model_read(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = make_spec(tmp_path, MODEL.replace("probability = 0.15", "probability = -0.15", 1))
    text = spec.read_text(encoding="utf-8")
    spec.write_text(text.replace("</Package>", "</Packag>"), encoding="utf-8")
    status, out = validate(capsys, str(spec))
    assert status == 1
    assert any(line.startswith(f"{spec}:") and ": error: " in line for line in out)
    users = tmp_path / "pill.users.toml"
    assert any(line.startswith(f"{users}:{_line_of('probability = 0.15')}: activities.hear_alarm."
                               "omission.probability: error: must be a probability")
               for line in out)
    assert out[-1].startswith("1 file checked (pill.users.toml beside it only read: the spec "
                              "has errors): 1 with errors (2 errors")


def test_with_a_broken_spec_validate_says_the_user_model_was_not_checked_against_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the lane check needs the spec: a model run would refuse for it is not called clean
    spec = make_spec(tmp_path, MODEL.replace("[activities.take_pill]",
                                             "[activities.take_pil]", 1))
    text = spec.read_text(encoding="utf-8")
    spec.write_text(text.replace("</Package>", "</Packag>"), encoding="utf-8")
    status, out = validate(capsys, str(spec))
    assert status == 1
    note = f"{tmp_path / 'pill.users.toml'}: info: the user model beside the spec was read"
    assert any(line.startswith(note) and "not checked against the spec's user lane: the "
               "spec could not be read" in line for line in out), out
    status, out = validate(capsys, "--json", str(spec))
    assert json.loads(out[0])["side_files"] == [
        {"path": str(tmp_path / "pill.users.toml"), "what": "user model", "checked": False,
         "why_not": "the spec could not be read", "given": False}]


def test_validate_picks_up_what_the_front_hall_picks_up(tmp_path: Path) -> None:
    spec = make_spec(tmp_path)
    assert side_files(spec) == {"user model": tmp_path / "pill.users.toml"}
    assert prepare(RunRequest(str(spec))).user_model == str(tmp_path / "pill.users.toml")


def test_every_shipped_spec_validates_clean_with_its_side_files(
        capsys: pytest.CaptureFixture[str]) -> None:
    specs = sorted(p for p in SPECS.iterdir() if p.suffix in (".xpdl", ".bpmn"))
    assert len(specs) >= 5
    status, out = validate(capsys, *map(str, specs))
    assert status == 0, out
    assert out == [(f"{len(specs)} files checked with medication_cart_guidance.world.toml, "
                    "medication_dispenser.users.toml, toy_sumo.world.toml, "
                    "vacuum_cleaner.world.toml beside them: no errors (0 errors, 0 warnings)")]
    for spec in specs:          # each one names what it read
        status, out = validate(capsys, str(spec))
        assert status == 0, out
        beside = [p.name for p in side_files(spec).values()] + [
            p.name for p in SPECS.glob(f"{spec.stem}.world.toml")]
        assert out[-1] == (f"1 file checked with {', '.join(beside)} beside it: no errors "
                           "(0 errors, 0 warnings)" if beside else
                           "1 file checked: no errors (0 errors, 0 warnings)")


def test_json_carries_the_line_of_a_side_files_warning_as_of_a_specs(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = make_spec(tmp_path, MODEL + "\n[activities.tkae_pill]\nduration = 3.0\n")
    line = len(MODEL.splitlines()) + 2
    _, out = validate(capsys, str(spec))
    assert out[0].startswith(f"{tmp_path / 'pill.users.toml'}:{line}: activities.tkae_pill: "
                             "warning: ")
    _, out = validate(capsys, "--json", str(spec))
    (problem,) = json.loads(out[0])["diagnostics"]
    assert (problem["path"], problem["line"], problem["key"], problem["code"]) == (
        str(tmp_path / "pill.users.toml"), line, "activities.tkae_pill", "unused-user-activity")


POPULATION = (SPECS / "medication_dispenser.population.toml").read_text(encoding="utf-8")


def test_a_user_model_given_is_checked_instead_of_the_companion(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--user-model`` checks the model (a population here) a run given it would read, in
    place of the companion, and the summary says it was given, not found beside the spec."""
    spec = make_spec(tmp_path, MODEL.replace("[activities.take_pill]", "[activities.take_pil]"))
    shutil.copyfile(SPECS / "medication_dispenser.users.toml",
                    tmp_path / "medication_dispenser.users.toml")   # what it extends
    population = tmp_path / "pill.population.toml"
    population.write_text(POPULATION, encoding="utf-8")
    assert validate(capsys, str(spec), "--user-model", str(population)) == (
        0, [("1 file checked with pill.population.toml as its user model: no errors "
             "(0 errors, 0 warnings)")])
    status, out = validate(capsys, str(spec), "--user-model", str(population), "--json")
    assert status == 0
    assert json.loads(out[0])["side_files"] == [
        {"path": str(population), "what": "user model", "checked": True, "why_not": None,
         "given": True}]


def test_a_population_evaluate_refuses_is_an_error_at_its_line_in_evaluates_words(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A population is the kind of file no run picks up by itself; validate checks it when
    given, and what ``opspec evaluate --user-model`` would refuse is an error at its line."""
    spec = make_spec(tmp_path)
    shutil.copyfile(SPECS / "medication_dispenser.users.toml",
                    tmp_path / "medication_dispenser.users.toml")
    population = tmp_path / "pill.population.toml"
    broken = POPULATION.replace('spearman = 0.3', 'spearman = 1.7', 1)
    assert broken != POPULATION
    population.write_text(broken, encoding="utf-8")
    line = next(n for n, text in enumerate(broken.splitlines(), start=1)
                if "spearman = 1.7" in text)
    status, out = validate(capsys, str(spec), "--user-model", str(population))
    assert status == 1
    problems = [text for text in out if ": error: " in text]
    assert len(problems) == 1 and problems[0].startswith(f"{population}:{line}")
    assert main(["evaluate", str(spec), "--user-model", str(population), "--users", "2",
                 "--days", "0.01", "--out", str(tmp_path / "out")]) == 2
    refused = capsys.readouterr().err.strip().removeprefix("opspec evaluate: ")
    assert problems[0].replace(": error: ", ": ", 1) == refused
