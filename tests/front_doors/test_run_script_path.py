"""``opspec.run(spec, script=PATH)`` reads the script file as ``opspec run --script PATH`` does."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import opspec
from opspec.errors import ConfigurationError
from opspec.testing import load_script

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
LATE = 'otherwise = "complete"\nsteps = [["after trg_2 400s", "press_report"]]\n'


def _trace(outcome: opspec.RunOutcome) -> list[tuple[float, str, str | None]]:
    assert outcome.trace is not None
    return [(e.time, e.kind, e.activity) for e in outcome.trace]


def test_a_script_path_runs_the_script_it_names(tmp_path: Path) -> None:
    script = tmp_path / "late.toml"
    script.write_text(LATE, encoding="utf-8")
    by_path = opspec.run(DISPENSER, seed=4, days=1, script=script)
    by_object = opspec.run(DISPENSER, seed=4, days=1, script=load_script(script))
    nobody = opspec.run(DISPENSER, seed=4, days=1, user=opspec.User.nobody())
    assert _trace(by_path) == _trace(by_object)
    assert _trace(by_path) != _trace(nobody)          # the script did act in the user lane
    assert _trace(opspec.run(DISPENSER, seed=4, days=1, script=str(script))) == _trace(by_path)


def test_a_missing_script_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigurationError, match="cannot read the script"):
        opspec.run(DISPENSER, seed=0, days=1, script=tmp_path / "absent.toml")


def test_a_bad_script_names_its_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"actions": "not a list"}))
    with pytest.raises(ConfigurationError) as caught:
        opspec.run(DISPENSER, seed=0, days=1, script=bad)
    assert "bad.json" in str(caught.value)
