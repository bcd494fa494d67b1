"""Outputs stay where the user put them: no output option may name a file the same command
reads (refused with exit status 2, both named, the input untouched), and a name from a spec
(a metric's Name) cannot lead a figure out of the evaluation's folder."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"


@pytest.fixture
def spec(tmp_path: Path) -> Path:
    shutil.copy(SPEC, tmp_path)
    shutil.copy(USERS, tmp_path)
    return tmp_path / SPEC.name


def _refused(capsys, argv: list[str], *named: Path) -> str:
    before = {path: path.read_bytes() for path in named}
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "refusing to overwrite it" in err
    for path, text in before.items():
        assert str(path) in err
        assert path.read_bytes() == text, f"{path} was changed"
    return err


def test_run_trace_may_not_replace_the_spec_or_its_user_model(spec: Path, capsys) -> None:
    err = _refused(capsys, ["run", str(spec), "--trace", str(spec), "--until", "60"], spec)
    assert "--trace" in err and "as SPEC" in err
    users = spec.with_name("medication_dispenser.users.toml")
    err = _refused(capsys, ["run", str(spec), "--trace", str(users), "--until", "60"], users)
    assert "companion user model" in err
    # through another spelling of the same path, too
    other = spec.parent / "." / spec.name
    _refused(capsys, ["run", str(spec), "--trace", str(other), "--until", "60"], spec)


def test_fit_output_may_not_replace_a_trace(spec: Path, tmp_path: Path, capsys) -> None:
    trace = tmp_path / "t.jsonl"
    assert main(["run", str(spec), "--trace", str(trace), "--until", "7200",
                 "--timeline", "none"]) == 0
    capsys.readouterr()
    err = _refused(capsys, ["fit", str(trace), "-o", str(trace)], trace)
    assert "-o" in err and "TRACE" in err


def test_walkthrough_record_may_not_replace_the_spec(spec: Path, capsys) -> None:
    # refused before the terminal interface starts
    _refused(capsys, ["walkthrough", str(spec), "--record", str(spec)], spec)


def test_evaluate_refuses_an_output_folder_that_holds_its_inputs(spec: Path, tmp_path: Path,
                                                                 capsys) -> None:
    out = tmp_path / "out"
    (out / "figures").mkdir(parents=True)
    inside = out / "figures" / SPEC.name
    shutil.copy(spec, inside)
    shutil.copy(spec.with_name(USERS.name), inside.with_name(USERS.name))
    _refused(capsys, ["evaluate", str(inside), "--users", "1", "--days", "1", "--workers",
                      "1", "--out", str(out)], inside)
    assert not (out / "results.sqlite").exists()
    template = out / "report.html"
    template.write_text("{{ title }}", encoding="utf-8")
    # (the template lies in the spec's folder too: trusted here, so the overwrite is what
    # refuses it)
    _refused(capsys, ["evaluate", str(spec), "--users", "1", "--days", "1", "--workers",
                      "1", "--out", str(out), "--report-template", str(template),
                      "--trust-spec-template"], template)


def test_a_metric_name_cannot_lead_a_figure_out_of_the_folder(spec: Path, tmp_path: Path,
                                                              capsys) -> None:
    text = spec.read_text(encoding="utf-8")
    assert text.count('Name="report_latency_s"') == 1
    spec.write_text(text.replace('Name="report_latency_s"', 'Name="../../escaped/x"'),
                    encoding="utf-8")
    assert main(["validate", str(spec)]) == 0
    err = capsys.readouterr().out
    assert "metric name '../../escaped/x' is not a simple identifier" in err
    out = tmp_path / "a" / "b" / "out"
    before = set(tmp_path.rglob("*"))
    assert main(["evaluate", str(spec), "--users", "2", "--days", "1", "--workers", "1",
                 "--out", str(out), "--quiet"]) == 0
    written = set(tmp_path.rglob("*")) - before
    assert written and all(p == out or out in p.parents or p in out.parents for p in written)
    assert not (tmp_path / "a" / "escaped").exists()
    assert [p.name for p in (out / "figures").glob("A-escaped_x-*.*")]      # svg by default


def test_file_name_keeps_simple_names_and_tames_the_rest() -> None:
    from opspec.files import file_name

    assert file_name("report_latency_s") == "report_latency_s"
    for hostile in ("../../x", "/etc/passwd", "a/b", "..", "", "x\x00y", "é" * 300):
        name = file_name(hostile)
        assert "/" not in name and name not in ("", ".", "..") and len(name) <= 89
        assert not name.startswith(".")
    assert file_name("a/b") != file_name("a:b")
