"""`opspec show`'s Modes line names the workflows each mode runs. It listed only the
<opspec:Mode Workflows="..."> attribute, which the bundled specs leave out (each process says
its mode with opspec:Mode), so it read 'run (initial): ; dock: '."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]


def test_modes_name_the_workflows_whose_directive_names_them(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(ROOT / "specs" / "vacuum_cleaner.xpdl")]) == 0
    modes = [line for line in capsys.readouterr().out.splitlines()
             if line.startswith("Modes:")]
    assert modes == [("Modes: run (initial): sense, avoid, wander, manoeuvre, arbitrate, "
                      "battery; dock: dock")]


def test_listed_workflows_and_a_source_are_shown(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    text = (ROOT / "specs" / "vacuum_cleaner.xpdl").read_text(encoding="utf-8")
    spec = tmp_path / "v.xpdl"
    spec.write_text(text.replace('<opspec:Mode Id="dock"/>',
                                 '<opspec:Mode Id="dock" Workflows="battery" '
                                 'Source="dock.xpdl"/>'), encoding="utf-8")
    (tmp_path / "dock.xpdl").write_text(text, encoding="utf-8")
    main(["show", str(spec)])
    modes = [line for line in capsys.readouterr().out.splitlines()
             if line.startswith("Modes:")]
    assert modes == [("Modes: run (initial): sense, avoid, wander, manoeuvre, arbitrate, "
                      "battery; dock: battery, dock, loads dock.xpdl")]
