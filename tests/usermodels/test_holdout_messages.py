"""`opspec fit --holdout K`: what it says when the persons cannot be split (a range of K that
works, or that none does), and a fold's own misfits told apart from the verdict over all
folds (Holm within a fold is not Holm over all of them)."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.commands.model_check import CrossValidation, fold_persons
from opspec.errors import UserModelError
from opspec.usermodels.check_report import CheckItem, CheckReport, finish
from opspec.usermodels.observations import Observations


def _obs(persons: int) -> Observations:
    obs = Observations()
    for i in range(persons):
        obs.person_of[(i, 1)] = f"P{i}"
    return obs


def test_three_persons_cannot_be_split_and_the_hint_says_so() -> None:
    paths = [Path(f"P{i}.jsonl") for i in range(3)]
    with pytest.raises(UserModelError) as caught:
        fold_persons(paths, _obs(3), 2)
    hint = caught.value.hint
    assert "4 persons or more" in hint
    assert "use 2 to 3" not in hint          # 2 folds was the K just refused


def test_the_hint_names_the_folds_that_work() -> None:
    paths = [Path(f"P{i}.jsonl") for i in range(5)]
    with pytest.raises(UserModelError) as caught:
        fold_persons(paths, _obs(5), 9)
    assert "use 3 to 5 folds" in caught.value.hint   # 2 folds leave 2 persons to fit on
    fold_persons(paths, _obs(5), 3)


def _item(name: str, p: float) -> CheckItem:
    return CheckItem(name, "duration", name, "test", 1.0, p, 2, 10,
                     {"value": 1.0}, {"value": 1.0, "low": 0.5, "high": 1.5})


def test_a_folds_own_misfit_is_not_the_verdict() -> None:
    one = CheckReport(finish([_item("walk duration", 0.02)], 0.05), 0.05, 2, 2, 99, 0, "")
    other = CheckReport(finish([_item(f"a{i} duration", 0.5) for i in range(4)], 0.05),
                        0.05, 2, 2, 99, 0, "")
    assert one.misfits                          # within its fold, Holm over 1 item
    cv = CrossValidation(((("P1", "P2"), one), (("P3", "P4"), other)), 0.05)
    assert cv.fits                              # over all 5 items: 0.02 x 5 = 0.1
    lines = cv.lines()
    assert lines[0] == ("fold 1/2: fitted without 2 person(s) (P1, P2), checked on them: "
                        "misfit within this fold (Holm over its 1 item(s), not over all "
                        "folds): walk duration")
    assert lines[1].endswith("checked on them: nothing misfits")
    assert "none of 5 item(s) over 2 folds misfits" in lines[-1]
