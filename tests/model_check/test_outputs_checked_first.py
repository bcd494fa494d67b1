"""`opspec fit -o FILE` and `opspec model-check --report DIR` say that they cannot write
their output before the work (fitting and bootstrapping, checking: minutes on a real
study), not after it, and create nothing when they cannot."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.commands import model_check
from opspec.evaluation.predictive import write_person_traces
from opspec.usermodels import fitting

HERE = Path(__file__).resolve().parent
SPEC = HERE.parents[1] / "specs" / "medication_dispenser.xpdl"
REFERENCE = HERE.parents[1] / "specs" / "medication_dispenser.users.toml"


@pytest.fixture(scope="module")
def people(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    return write_person_traces(SPEC, REFERENCE, tmp_path_factory.mktemp("people"),
                               people=range(2), seed=5, days=1)


@pytest.fixture
def no_work(monkeypatch: pytest.MonkeyPatch) -> None:
    """The work itself fails the test: the refusal must come before it."""
    def work(*_args: object, **_kwargs: object) -> None:
        raise AssertionError("the work started before the output was checked")

    monkeypatch.setattr(fitting, "fit_traces", work)
    monkeypatch.setattr(model_check, "check_model", work)


def test_fit_refuses_an_output_it_cannot_write_before_fitting(
        people: list[Path], tmp_path: Path, no_work: None,
        capsys: pytest.CaptureFixture[str]) -> None:
    blocker = tmp_path / "notes.txt"
    blocker.write_text("a file, not a folder\n", encoding="utf-8")
    target = blocker / "model.toml"
    assert main(["fit", *map(str, people), "-o", str(target)]) == 2
    err = capsys.readouterr().err
    assert f"opspec fit: cannot write {target}: {blocker} is a file, not a folder" in err
    assert "Traceback" not in err


def test_model_check_refuses_a_report_folder_it_cannot_write_before_checking(
        people: list[Path], tmp_path: Path, no_work: None,
        capsys: pytest.CaptureFixture[str]) -> None:
    blocker = tmp_path / "notes.txt"
    blocker.write_text("a file, not a folder\n", encoding="utf-8")
    report = blocker / "report"
    assert main(["model-check", str(REFERENCE), *map(str, people),
                 "--report", str(report)]) == 2
    err = capsys.readouterr().err
    assert f"opspec model-check: cannot write {report}: {blocker} is a file, not a folder" \
        in err


def test_a_writable_output_creates_nothing_before_the_work(
        people: list[Path], tmp_path: Path, no_work: None,
        capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "new" / "folders" / "model.toml"
    assert main(["fit", *map(str, people), "-o", str(target)]) != 0
    assert "the work started" in capsys.readouterr().err     # it got as far as the work
    assert list(tmp_path.iterdir()) == []           # the probe made and removed its file
