"""What used to show only mid-run is found by ``opspec validate`` at the spec's line: a mode
whose Source file is missing, and a world that cannot be built. ``opspec run``, ``evaluate``
and ``walkthrough`` refuse a spec validate rejects (exit 1, the errors with path:line)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.cli import main

SPECS = Path(__file__).resolve().parents[2] / "specs"
WORLD = '<ExtendedAttribute Name="opspec:World" Value="vacuum-room"/>'
MODES = '<opspec:Mode Id="dock"/>'


def vacuum(tmp_path: Path, old: str, new: str) -> Path:
    text = (SPECS / "vacuum_cleaner.xpdl").read_text(encoding="utf-8")
    assert old in text
    spec = tmp_path / "vacuum.xpdl"
    spec.write_text(text.replace(old, new, 1), encoding="utf-8")
    shutil.copy(SPECS / "vacuum_cleaner.world.toml", tmp_path)
    return spec


def line_of(path: Path, needle: str) -> int:
    return next(n for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
                if needle in line)


def validate(capsys: pytest.CaptureFixture[str], spec: Path) -> tuple[int, str]:
    status = main(["validate", str(spec)])
    return status, capsys.readouterr().out


def test_a_mode_source_that_does_not_exist_is_reported_at_the_mode(tmp_path, capsys):
    spec = vacuum(tmp_path, MODES, '<opspec:Mode Id="dock" Source="nosuch_dock.xpdl"/>')
    status, out = validate(capsys, spec)
    assert status == 1
    assert f"vacuum.xpdl:{line_of(spec, 'nosuch_dock')}: error:" in out
    assert "mode 'dock' loads 'nosuch_dock.xpdl', which does not exist" in out
    assert "relative to this spec's folder" in out


def test_a_mode_source_with_errors_is_reported_at_the_mode(tmp_path, capsys):
    (tmp_path / "dock.xpdl").write_text("<Package>", encoding="utf-8")
    spec = vacuum(tmp_path, MODES, '<opspec:Mode Id="dock" Source="dock.xpdl"/>')
    status, out = validate(capsys, spec)
    assert status == 1
    assert "mode 'dock' loads 'dock.xpdl', which has errors" in out


WORLD_CASES = [
    (WORLD.replace("vacuum-room", "moon-base"), "unknown world 'moon-base'"),
    (WORLD + '<ExtendedAttribute Name="opspec:WorldFile" Value="nosuch.toml"/>',
     "cannot read the world file"),
    (WORLD.replace("/>", '><opspec:Parameter Name="colour" Value="red"/></ExtendedAttribute>'),
     "has no parameter 'colour'"),
    (WORLD.replace("/>", '><opspec:Parameter Name="start" Value="[1.8, 1.9, 0.0]"/>'
                         "</ExtendedAttribute>"), "puts the robot in a wall or an obstacle"),
    (WORLD.replace("/>", '><opspec:Parameter Name="width" Value="wide"/></ExtendedAttribute>'),
     "width must be a number, not 'wide'"),
    (WORLD.replace("/>", '><opspec:Parameter Name="obstacles" Value="[[1, 2, 3]]"/>'
                         "</ExtendedAttribute>"), "must be a list of 4 numbers"),
]


@pytest.mark.parametrize("declaration, message", WORLD_CASES, ids=[
    "unknown-world", "missing-world-file", "unknown-parameter", "start-in-obstacle",
    "width-not-a-number", "obstacle-not-a-box"])
def test_a_world_that_cannot_be_built_is_reported_at_its_line(tmp_path, capsys, declaration,
                                                              message):
    spec = vacuum(tmp_path, WORLD, declaration)
    status, out = validate(capsys, spec)
    assert status == 1
    line = line_of(spec, 'Name="opspec:World"')
    assert f"vacuum.xpdl:{line}: error:" in out
    assert message in out
    assert "not supported between" not in out and "could not convert" not in out


def test_the_bundled_specs_validate_clean(capsys):
    status = main(["validate", str(SPECS)])
    assert status == 0, capsys.readouterr().out


UNDECLARED_MODE = ('<opspec:ModeChange To="dock"/>', '<opspec:ModeChange To="sleep"/>')


@pytest.mark.parametrize("command", [
    ["run", "--until", "10"],
    ["evaluate", "--users", "1", "--workers", "1"],
    ["walkthrough"],
], ids=["run", "evaluate", "walkthrough"])
def test_a_spec_validate_rejects_is_not_executed(tmp_path, capsys, command):
    spec = vacuum(tmp_path, *UNDECLARED_MODE)
    name, *options = command
    extra = ["--out", str(tmp_path / "ev")] if name == "evaluate" else []
    status = main([name, str(spec), *options, *extra])
    captured = capsys.readouterr()
    assert status == 1
    line = line_of(spec, 'To="sleep"')
    assert f"vacuum.xpdl:{line}:" in captured.err
    assert "switches to mode 'sleep', which the package does not declare" in captured.err
    assert "mode.changed" not in captured.out and "metrics" not in captured.out
    assert not (tmp_path / "ev").exists()


def test_every_error_is_listed_when_a_run_is_refused(tmp_path, capsys):
    spec = vacuum(tmp_path, *UNDECLARED_MODE)
    text = spec.read_text(encoding="utf-8").replace(
        '<opspec:Input Ref="wander_cmd"/>', '<opspec:Input Ref="nosuch"/>', 1)
    spec.write_text(text, encoding="utf-8")
    assert main(["run", str(spec), "--until", "10"]) == 1
    err = capsys.readouterr().err
    assert "(and 1 more)" in err
    assert "reads 'nosuch'" in err and "mode 'sleep'" in err


def test_check_counts_a_missing_mode_source_and_an_unbuildable_world_as_spec_errors(tmp_path,
                                                                                   capsys):
    spec = vacuum(tmp_path, WORLD, WORLD.replace("vacuum-room", "moon-base"))
    text = spec.read_text(encoding="utf-8").replace(MODES, '<opspec:Mode Id="dock" '
                                                           'Source="nosuch_dock.xpdl"/>')
    spec.write_text(text, encoding="utf-8")
    status = main(["check", str(spec)])
    out = capsys.readouterr().out
    assert status == 1
    assert "unknown world 'moon-base'" in out and "nosuch_dock.xpdl" in out
    assert "2 spec error(s)" in out
