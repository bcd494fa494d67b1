"""compile, preprocess and show refuse an -o naming a file the spec reads: its world file, a
mode's spec (and for show, the companion user model, as compile and preprocess refused it
already). Each wrote its output over the world file and exited 0."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"


@pytest.fixture
def vacuum(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    shutil.copyfile(SPECS / "vacuum_cleaner.xpdl", "vacuum.xpdl")
    shutil.copyfile(SPECS / "vacuum_cleaner.world.toml", "vacuum_cleaner.world.toml")
    return Path("vacuum.xpdl")


@pytest.mark.parametrize(("command", "example"), [
    ("compile", "vacuum.wfs beside it"), ("preprocess", "vacuum.std.xpdl"),
    ("show", "vacuum.txt")])
def test_the_world_file_is_not_overwritten(vacuum: Path, command: str, example: str,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    world = Path("vacuum_cleaner.world.toml")
    before = world.read_bytes()
    assert main([command, str(vacuum), "-o", str(world)]) == 2
    assert world.read_bytes() == before
    assert capsys.readouterr().err == (
        f"opspec {command}: -o vacuum_cleaner.world.toml is the file this command reads as "
        f"its opspec:WorldFile; refusing to overwrite it (give -o another file, e.g. "
        f"{example})\n")


def test_a_mode_s_spec_is_not_overwritten(vacuum: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    shutil.copyfile(SPECS / "vacuum_cleaner.xpdl", "dock.xpdl")
    vacuum.write_text(vacuum.read_text(encoding="utf-8").replace(
        '<opspec:Mode Id="dock"/>', '<opspec:Mode Id="dock" Source="dock.xpdl"/>'),
        encoding="utf-8")
    before = Path("dock.xpdl").read_bytes()
    for command in ("compile", "preprocess", "show"):
        assert main([command, str(vacuum), "-o", "dock.xpdl"]) == 2, command
        assert "as the Source of its mode 'dock'" in capsys.readouterr().err
    assert Path("dock.xpdl").read_bytes() == before


def test_show_keeps_the_companion_user_model(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    shutil.copyfile(SPECS / "medication_dispenser.xpdl", "d.xpdl")
    shutil.copyfile(SPECS / "medication_dispenser.users.toml", "d.users.toml")
    assert main(["show", "d.xpdl", "-o", "d.users.toml"]) == 2
    assert "as SPEC's companion user model; refusing" in capsys.readouterr().err
    assert Path("d.users.toml").read_bytes() == (
        SPECS / "medication_dispenser.users.toml").read_bytes()
