"""The report of a spec other than the dispenser speaks of that spec: the stove guard that
``opspec new --template stove`` writes is no dispenser, and its report said the user was busy
"for one dose", that a rate per offer is not the model's "probability per dose", and that a
slow walker "is slow at every dose"."""

from __future__ import annotations

import pytest

from opspec.cli import main


@pytest.fixture(scope="module")
def stove_report(tmp_path_factory: pytest.TempPathFactory) -> str:
    pytest.importorskip("matplotlib")
    folder = tmp_path_factory.mktemp("stove")
    assert main(["new", str(folder / "stove"), "--template", "stove"]) == 0
    out = folder / "run"
    assert main(["evaluate", str(folder / "stove" / "stove.xpdl"), "--users", "4", "--days",
                 "1", "--workers", "1", "--quiet", "--out", str(out)]) == 0
    return (out / "report.md").read_text(encoding="utf-8")


def test_the_busy_rule_is_in_the_spec_s_terms(stove_report: str) -> None:
    assert "for one dose" not in stove_report
    assert ("While busy with go\\_to\\_stove, press\\_here in one workflow instance, the user "
            "ignores hear\\_alert from other instances") in stove_report


def test_the_rates_per_offer_and_the_units_say_no_dose(stove_report: str) -> None:
    assert "probability per dose" not in stove_report
    assert "probability per workflow instance" in stove_report
    assert "slow at every dose" not in stove_report
