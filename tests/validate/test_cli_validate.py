"""``opspec validate`` on real files: one fixture per invalid case under ``data/``, exit
statuses 0/1/2, ``--strict``, ``--json``, folders and missing paths."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.xpdl.validate import merge_diagnostics, spec_files, validate_file

DATA = Path(__file__).parent / "data"


def line_of(path: Path, needle: str) -> int:
    """The 1-based line of the first line of ``path`` containing ``needle``."""
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if needle in line:
            return number
    raise AssertionError(f"{needle!r} not in {path}")


# file, expected code, text on the line the diagnostic must point at
INVALID = [
    ("dangling_transition.xpdl", "dangling-transition", 'Id="T7"'),
    ("duplicate_activity_id.xpdl", "duplicate-id", 'Activity Id="work"'),   # the 2nd one
    ("undefined_participant.xpdl", "undefined-participant", "robot"),
    ("undefined_application.xpdl", "undefined-application", 'TaskApplication Id="beep"'),
    ("undefined_data_field.xpdl", "undefined-data-field", "level &gt; 3"),
    ("undefined_subflow.xpdl", "undefined-subflow", 'SubFlow Id="Refill"'),
    ("no_start_activity.xpdl", "no-start-activity", "<WorkflowProcess "),
    ("deadline_without_exception.xpdl", "deadline-without-exception-path", "<Deadline"),
    ("and_join_deadlock.xpdl", "and-join-deadlock", '<Activity Id="J">'),
    ("bad_condition.xpdl", "bad-condition", "n &gt;&gt;&gt;"),
    ("not_well_formed.xpdl", "not-well-formed", "</WorkflowProcess>"),       # the last one
    ("unknown_version.xpdl", "unknown-version", "<Package "),
]


def _expected_line(name: str, needle: str) -> int:
    path = DATA / name
    hits = [n for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1)
            if needle in line]
    if name == "duplicate_activity_id.xpdl":
        return hits[1]           # reported at the second activity 'work'
    if name == "not_well_formed.xpdl":
        return hits[-1]          # the stray </WorkflowProcess> closing <WorkflowProcesses>
    return hits[0]


@pytest.mark.parametrize(("name", "code", "needle"), INVALID, ids=[c for _, c, _ in INVALID])
def test_each_invalid_file_is_reported_with_its_code_at_its_line(
        name: str, code: str, needle: str, capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / name
    report = validate_file(path)
    found = [d for d in report.diagnostics if d.code == code]
    assert found, [str(d) for d in report.diagnostics]
    line = _expected_line(name, needle)
    assert found[0].location.line == line
    assert not report.ok
    assert main(["validate", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{path}:{line}: error: " in out
    assert out.rstrip().endswith("1 file checked: 1 with errors (1 error, 0 warnings)")


def test_every_invalid_fixture_has_exactly_one_problem() -> None:
    for name, code, _ in INVALID:
        assert [d.code for d in validate_file(DATA / name).diagnostics] == [code], name


def test_a_valid_file_exits_0_with_a_summary(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", str(DATA / "valid.xpdl")]) == 0
    assert capsys.readouterr().out == "1 file checked: no errors (0 errors, 0 warnings)\n"


def test_warnings_pass_unless_strict(capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / "warning_unreachable.xpdl"
    line = line_of(path, 'Activity Id="orphan"')
    assert main(["validate", str(path)]) == 0
    assert f"{path}:{line}: warning: activity 'orphan'" in capsys.readouterr().out
    assert main(["validate", "--strict", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{path}:{line}: error: activity 'orphan'" in out
    assert "1 with errors (1 error, 0 warnings)" in out


def test_json_prints_one_object_per_file(capsys: pytest.CaptureFixture[str]) -> None:
    paths = [DATA / "valid.xpdl", DATA / "dangling_transition.xpdl", DATA / "not_well_formed.xpdl"]
    assert main(["validate", "--json", *map(str, paths)]) == 1
    lines = capsys.readouterr().out.splitlines()
    objects = [json.loads(line) for line in lines]
    assert [o["path"] for o in objects] == [str(p) for p in paths]
    assert [o["ok"] for o in objects] == [True, False, False]
    assert [o["version"] for o in objects] == ["2.1", "2.1", None]
    assert objects[0]["diagnostics"] == []
    diagnostic = objects[1]["diagnostics"][0]
    assert set(diagnostic) == {"path", "line", "severity", "code", "message", "hint"}
    assert diagnostic["code"] == "dangling-transition"
    assert diagnostic["severity"] == "error"
    assert diagnostic["line"] == line_of(paths[1], 'Id="T7"')
    assert diagnostic["message"].startswith("Transition 'T7' points to activity 'A99'")


def test_json_with_strict_marks_warnings_as_errors(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", "--json", "--strict", str(DATA / "warning_unreachable.xpdl")]) == 1
    record = json.loads(capsys.readouterr().out)
    assert record["ok"] is False
    assert [d["severity"] for d in record["diagnostics"]] == ["error"]


def test_a_folder_validates_every_spec_below_it_in_sorted_order(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "sub").mkdir()
    shutil.copy(DATA / "valid.xpdl", tmp_path / "b.xpdl")
    shutil.copy(DATA / "dangling_transition.xpdl", tmp_path / "sub" / "a.XML")
    shutil.copy(DATA / "valid.xpdl", tmp_path / "a.xml")
    (tmp_path / "notes.txt").write_text("not a spec")
    files, problems = spec_files([tmp_path])
    assert problems == []
    assert [p.relative_to(tmp_path).as_posix() for p in files] == ["a.xml", "b.xpdl", "sub/a.XML"]
    assert main(["validate", str(tmp_path)]) == 1
    out = capsys.readouterr().out
    assert "sub/a.XML:" in out and "3 files checked: 1 with errors" in out


def test_the_fixture_folder_reports_every_problem_at_once(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", str(DATA)]) == 1
    out = capsys.readouterr().out
    for name, code, _ in INVALID:
        assert str(DATA / name) in out, code
    total = len(list(DATA.glob("*.xpdl")))
    assert f"{total} files checked: {len(INVALID)} with errors" in out


def test_a_missing_path_exits_2_but_the_other_paths_are_still_checked(
        capsys: pytest.CaptureFixture[str]) -> None:
    missing = DATA / "no-such-file.xpdl"
    assert main(["validate", str(missing), str(DATA / "dangling_transition.xpdl")]) == 2
    captured = capsys.readouterr()
    assert f"opspec validate: {missing}: no such file or folder" in captured.err
    assert "dangling-transition" not in captured.out      # codes are not printed in text
    assert "Transition 'T7'" in captured.out


def test_an_empty_folder_is_a_usage_error(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", str(tmp_path)]) == 2
    assert "no *.xpdl or *.xml file" in capsys.readouterr().err


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads anything")
def test_an_unreadable_file_is_an_io_error(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "locked.xpdl"
    shutil.copy(DATA / "valid.xpdl", path)
    path.chmod(0)
    try:
        assert main(["validate", str(path)]) == 2
    finally:
        path.chmod(0o644)
    assert f"{path}: error: cannot read the file" in capsys.readouterr().out


def test_no_path_at_all_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["validate"])
    assert exit_info.value.code == 2


def test_problems_found_by_both_reader_and_checks_are_listed_once() -> None:
    where = SourceLocation("a.xpdl", 7)
    reader = Diagnostic(where, Severity.ERROR, "unresolved-subflow", "SubFlow calls 'X'")
    restated = Diagnostic(where, Severity.ERROR, "undefined-subflow", "activity calls 'X'")
    same = Diagnostic(SourceLocation("a.xpdl", 3), Severity.WARNING, "c", "m")
    merged = merge_diagnostics([reader, same], [restated, same])
    assert merged == (same, reader)


def test_a_subflow_missing_from_the_external_packages_is_reported_once(tmp_path: Path) -> None:
    text = (DATA / "undefined_subflow.xpdl").read_text(encoding="utf-8").replace(
        "  <WorkflowProcesses>",
        '  <ExternalPackages><ExternalPackage Id="lib" href="valid.xpdl"/></ExternalPackages>\n'
        "  <WorkflowProcesses>")
    shutil.copy(DATA / "valid.xpdl", tmp_path / "valid.xpdl")
    (tmp_path / "caller.xpdl").write_text(text, encoding="utf-8")
    report = validate_file(tmp_path / "caller.xpdl")
    about_refill = [d for d in report.diagnostics if "'Refill'" in d.message]
    assert [d.code for d in about_refill] == ["unresolved-subflow"]


def test_every_code_the_reader_emits_is_documented() -> None:
    import re

    root = Path(__file__).resolve().parents[2]
    # the reader and the modules it reads with (bytes, the safe parse, its errors)
    reader = "".join((root / "opspec" / "xpdl" / name).read_text()
                     for name in ("reader.py", "read_bytes.py", "read_errors.py", "safe_xml.py"))
    codes = set(re.findall(r'XmlReadError\(\s*"([a-z-]+)"', reader))
    sisarl = (root / "opspec" / "xpdl" / "sisarl.py").read_text()
    codes |= {"too-many-attributes"} & set(re.findall(r'"error", "([a-z-]+)"', sisarl))
    assert {"doctype", "resource-limit", "too-many-attributes"} <= codes
    docs = (root / "docs" / "validation.md").read_text()
    assert sorted(c for c in codes if f"`{c}`" not in docs) == []


def test_a_command_module_that_fails_to_import_breaks_only_that_command(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import opspec.cli

    (tmp_path / "opspec_broken_command_for_test.py").write_text("def register(:\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(opspec.cli, "COMMAND_MODULES",
                        (*opspec.cli.COMMAND_MODULES, "opspec_broken_command_for_test"))
    assert main(["validate", str(DATA / "valid.xpdl")]) == 0
    capsys.readouterr()
    assert main(["opspec-broken-command-for-test", "x", "--y"]) == 70
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "SyntaxError" in err and "cannot be loaded" in err


def test_a_broken_command_keeps_the_name_it_is_typed_with(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # model_check's command is `model-check`: its stand-in must answer to that name, alone
    # (`opspec model-check ...` builds its parser alone) or in the full list
    import importlib
    import types

    import opspec.cli

    def import_module(name: str) -> object:
        if name == "opspec.commands.model_check":
            raise RuntimeError("broken on purpose")
        return importlib.import_module(name)

    monkeypatch.setattr(opspec.cli, "importlib", types.SimpleNamespace(
        import_module=import_module))
    assert main(["model-check", "m.toml", "t.jsonl"]) == 70
    err = capsys.readouterr().err
    assert "the 'model-check' command cannot be loaded (RuntimeError: broken on purpose)" in err
    listed = opspec.cli._subparsers(opspec.cli.build_parser())
    assert "model-check" in listed and "model_check" not in listed


@pytest.mark.skipif(os.name != "posix", reason="symbolic links")
def test_a_folder_scan_reports_a_broken_symlink(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    shutil.copy(DATA / "valid.xpdl", tmp_path / "a.xpdl")
    (tmp_path / "broken.xpdl").symlink_to(tmp_path / "gone.xpdl")
    assert main(["validate", str(tmp_path)]) == 2
    captured = capsys.readouterr()
    assert f"{tmp_path / 'broken.xpdl'}: broken symbolic link" in captured.err
    assert "1 file checked" in captured.out
    files, problems = spec_files([tmp_path])
    assert files == [tmp_path / "a.xpdl"] and len(problems) == 1
