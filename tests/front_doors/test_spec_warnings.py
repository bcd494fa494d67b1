"""A spec's warnings reach the person through every front door (issue 27): what ``opspec
validate`` warns about (here an activity set no block uses) is printed by ``opspec run`` and
comes back, the same, in the outcome of ``opspec.run``, of a run built by the run builder
itself (``opspec.runs.build``: the gate and its warnings are the loader's, so no door skips
them) and in ``simulate()``'s result (the pytest plugin shows them: tests/testing_plugin)."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec import runs
from opspec.cli import main
from opspec.request import RunRequest, prepare
from opspec.testing import simulate

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
UNUSED_SET = ('<ActivitySets><ActivitySet Id="never_used"><Activities><Activity Id="idle">'
              '<Route/></Activity></Activities></ActivitySet></ActivitySets>\n      ')


@pytest.fixture
def warned(tmp_path: Path) -> Path:
    text = DISPENSER.read_text(encoding="utf-8")
    at = text.index("<Activities>", text.index('<WorkflowProcess Id="timer_workflow"'))
    spec = tmp_path / "warned.xpdl"
    spec.write_text(text[:at] + UNUSED_SET + text[at:], encoding="utf-8")
    return spec


def test_every_door_hands_back_validates_warnings(warned: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", str(warned)]) == 0
    (said,) = [line for line in capsys.readouterr().out.splitlines() if ": warning: " in line]
    assert said.startswith(f"{warned}:79: warning: activity set 'never_used'")

    assert main(["run", str(warned), "--until", "3600", "--no-user"]) == 0
    assert said in capsys.readouterr().err
    doors = {
        "opspec.run": opspec.run(warned, until=3600, no_user=True).warnings,
        "prepare().execute": prepare(RunRequest(warned, until=3600, no_user=True)
                                     ).execute().warnings,
        "runs.build(path)": runs.build(warned, until=3600).execute().warnings,
        "runs.load(path)": runs.load(warned).warnings,
        "simulate": simulate(warned, until=3600, no_user=True).warnings,
    }
    for door, warnings in doors.items():
        assert [str(w) for w in warnings] == [said], door


def test_a_spec_without_warnings_gives_none(tmp_path: Path) -> None:
    assert opspec.run(DISPENSER, until=3600, no_user=True).warnings == ()
    assert simulate(DISPENSER, until=3600, no_user=True).warnings == ()
