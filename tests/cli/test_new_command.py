"""`opspec new NAME [--template pill|stove]`: a small spec, its user model and its tests that
validate, run, evaluate, pass `opspec check` and pass their own tests as written; an existing
folder is never touched."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.commands.new import SHAPES, TEMPLATES, identifier, render

#: Per template: the metric counting the device's sessions (one per dose / cooking session),
#: how many a day, the two outcomes that partition them, and the ratio the evaluation shows.
SHAPE = {
    "pill": ("doses_due", 2, ("doses_taken", "doses_missed"), "taken_rate"),
    "stove": ("sessions", 1, ("confirmed", "power_cuts"), "cut_rate"),
}


@pytest.fixture(scope="module", params=sorted(SHAPES))
def template(request: pytest.FixtureRequest) -> str:
    return str(request.param)


@pytest.fixture(scope="module")
def scaffold(tmp_path_factory: pytest.TempPathFactory, template: str) -> Path:
    """One generated folder per template, shared by the tests that only read it."""
    folder = tmp_path_factory.mktemp(f"new-{template}") / "pill-box"
    args = ["new", str(folder)] + (["--template", template] if template != "pill" else [])
    assert main(args) == 0
    return folder


def test_writes_the_spec_its_user_model_its_tests_and_a_readme(scaffold: Path) -> None:
    assert sorted(p.name for p in scaffold.iterdir()) == sorted(
        ["pill-box.xpdl", "pill-box.users.toml", "test_pill_box.py", "README.md"])
    spec = (scaffold / "pill-box.xpdl").read_text(encoding="utf-8")
    assert 'Id="pill_box"' in spec and "$" not in spec
    assert '"pill-box.xpdl"' in (scaffold / "test_pill_box.py").read_text(encoding="utf-8")


def test_validates_without_errors_or_warnings_also_against_the_schema(
        scaffold: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", "--schema", "--json", str(scaffold / "pill-box.xpdl")]) == 0
    (report,) = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert report["diagnostics"] == []


def test_is_sound(scaffold: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(scaffold / "pill-box.xpdl")]) == 0
    assert "2 of 2 process level(s) sound, 0 problem(s)" in capsys.readouterr().out


def test_runs_a_day_with_its_user_model(scaffold: Path, template: str,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    sessions, per_day, (good, bad), _ = SHAPE[template]
    assert main(["run", str(scaffold / "pill-box.xpdl"), "--json"]) == 0
    metrics = json.loads(capsys.readouterr().out)["metrics"]
    assert metrics[sessions]["total"] == per_day     # 09:00 and 21:00; dinner at 18:00
    assert metrics[good]["total"] + metrics[bad]["total"] == per_day


def test_evaluates_20_users_over_2_days(scaffold: Path, tmp_path: Path, template: str,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    status = main(["evaluate", str(scaffold / "pill-box.xpdl"), "--users", "20", "--days", "2",
                   "--out", str(tmp_path / "run"), "--workers", "1"])
    assert status == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "20 users x 2 days" in out and SHAPE[template][3] in out
    assert (tmp_path / "run" / "report.html").is_file()


def test_its_own_tests_pass_with_pytest_as_written(scaffold: Path) -> None:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "TEXTUAL_"))}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"],
                          cwd=scaffold, env=env, capture_output=True, text=True, timeout=300,
                          check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "3 passed" in done.stdout


def test_refuses_an_existing_folder_in_one_line_and_leaves_it_alone(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "mine.xpdl").write_text("my work", encoding="utf-8")
    assert main(["new", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "already exists" in err
    assert [p.name for p in folder.iterdir()] == ["mine.xpdl"]
    assert (folder / "mine.xpdl").read_text(encoding="utf-8") == "my work"


def test_refuses_an_existing_file_too(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "taken").write_text("x", encoding="utf-8")
    assert main(["new", str(tmp_path / "taken")]) == 2
    assert "already exists" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["a b", "-x", "a--b", "pill<box>"])
def test_refuses_a_name_that_cannot_name_files_and_ids(
        name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["new", str(tmp_path / name)]) == 2
    assert capsys.readouterr().err.count("\n") == 1
    assert not (tmp_path / name).exists()


def test_names_become_identifiers() -> None:
    assert identifier("pill-box.v2") == "pill_box_v2"
    assert identifier("2pills") == "spec_2pills"


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_templates_are_package_data_and_fully_substituted(shape: str) -> None:
    files = render("demo", shape)
    assert len(files) == len(TEMPLATES)
    assert all("${" not in text for text in files.values())


def test_an_unknown_template_is_a_usage_error_naming_the_choices(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["new", str(tmp_path / "x"), "--template", "toaster"])
    assert exit_.value.code == 2
    assert capsys.readouterr().err == ("opspec new: --template takes one of pill, stove, not "
                                       "'toaster'\n")
    assert not (tmp_path / "x").exists()


def test_pytest_comes_with_opspec_not_only_with_its_test_extras() -> None:
    """The spec tests `opspec new` writes (and the README's "Specs as tests") run on pytest,
    the host of opspec's pytest plugin: it must be a dependency of the plain install."""
    import tomllib

    project = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml")
                            .read_text(encoding="utf-8"))["project"]
    assert any(d.replace(" ", "").startswith("pytest>") for d in project["dependencies"])


@pytest.mark.parametrize("shape", sorted(SHAPES))
@pytest.mark.parametrize("name", ["pb", "a-much-longer-name"])
def test_the_readmes_commands_keep_their_comments_in_one_column(shape: str, name: str) -> None:
    readme = render(name, shape)["README.md"]
    block = readme.split("```sh\n", 1)[1].split("```", 1)[0]
    columns = {line.index("  #") for line in block.splitlines() if "  #" in line}
    assert len(columns) == 1, block
