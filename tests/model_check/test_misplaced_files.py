"""A spec or a user model among the TRACE files of ``opspec fit`` / ``model-check``, and
traces or a spec as model-check's MODEL (the arguments swapped): each is refused in one line
saying what the file is and where it goes. They were read as what they are not: "not valid
JSON" at line 1 of a spec or user model, "not valid TOML" of a trace, "no user model file or
preset called 'traces'" of a folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
MODEL = ROOT / "specs" / "medication_dispenser.users.toml"


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("traces")
    assert main(["run", str(SPEC), "--days", "1", "--timeline", "none",
                 "--trace", str(folder / "a.jsonl")]) == 0
    return folder


def _line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "not valid" not in err and "Traceback" not in err
    return err


@pytest.mark.parametrize("command", ["fit", "model-check"])
def test_a_spec_as_a_trace(command: str, traces: Path, tmp_path: Path,
                           capsys: pytest.CaptureFixture[str]) -> None:
    argv = ([command, str(traces / "a.jsonl"), str(SPEC), "-o", str(tmp_path / "m.toml")]
            if command == "fit" else [command, str(MODEL), str(traces / "a.jsonl"), str(SPEC)])
    capsys.readouterr()
    assert main(argv) == 2
    line = _line(capsys)
    assert f"{SPEC}: a spec (XPDL), not a trace" in line and "--trace FILE" in line
    assert not (tmp_path / "m.toml").exists()


def test_a_user_model_as_a_trace_of_fit(traces: Path, tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["fit", str(MODEL), "-o", str(tmp_path / "m.toml")]) == 2
    line = _line(capsys)
    assert f"{MODEL}: a user model, not a trace" in line and "-o MODEL.toml" in line


@pytest.mark.parametrize("model", ["folder", "trace"])
def test_model_check_s_arguments_swapped(model: str, traces: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    given = traces if model == "folder" else traces / "a.jsonl"
    capsys.readouterr()
    assert main(["model-check", str(given), str(MODEL)]) == 2
    line = _line(capsys)
    assert f"{given}: a {model}, not a user model" in line
    assert "opspec model-check MODEL TRACE..." in line


def test_a_spec_as_the_model(traces: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["model-check", str(SPEC), str(traces)]) == 2
    line = _line(capsys)
    assert f"{SPEC}: a spec (XPDL), not a user model" in line and "--spec SPEC" in line


def test_a_trace_is_still_read(traces: Path, tmp_path: Path) -> None:
    """What fit reads is still read: a .jsonl trace is not refused (the check looks only for
    plain specs and user models)."""
    assert main(["fit", str(traces / "a.jsonl"), "-o", str(tmp_path / "m.toml"),
                 "--draws", "0"]) == 0
