"""A hand-edited script's wrong value is named with the objects it is in: the message said
only "expected str, got 5", which of a script's thousands of values it was left to guess."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.errors import SpecError
from opspec.model import codec
from opspec.xpdl.loader import load_package

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def document() -> dict:
    package = load_package(ROOT / "specs" / "medication_dispenser.xpdl").package
    assert package is not None
    return codec.dump(package)


def test_a_wrong_value_deep_in_the_script_is_placed(tmp_path: Path, document: dict) -> None:
    notify = next(p for p in document["package"]["processes"] if p["id"] == "notify_workflow")
    wait = next(a for a in notify["activities"] if a["id"] == "wait_report")
    wait["deadlines"][0]["execution"] = "SOON"
    path = tmp_path / "edited.wfs"
    path.write_text(json.dumps(document), encoding="utf-8")
    with pytest.raises(SpecError) as caught:
        codec.read_wfs(path)
    assert caught.value.message == (
        f"{path}: corrupt workflow script: 'SOON' is not a Execution (in Package "
        "'medication_dispenser' > WorkflowProcess 'notify_workflow' > Activity 'wait_report' "
        "> Deadline, field execution)")


def test_an_object_whose_id_is_wrong_is_named_by_its_kind(document: dict) -> None:
    document["package"]["processes"][0]["activities"][0]["id"] = 5
    with pytest.raises(SpecError, match=(
            r"expected str, got 5 \(in Package 'medication_dispenser' > WorkflowProcess "
            r"'timer_workflow' > Activity, field id\) \(recompile")):
        codec.load(document)


def test_a_wrong_value_of_the_package_itself_names_the_field(document: dict) -> None:
    document["package"]["id"] = 7
    with pytest.raises(SpecError, match=r"expected str, got 7 \(in Package, field id\) \(recompile"):
        codec.load(document)
