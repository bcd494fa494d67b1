"""The time a wrong pick costs when the wrong picks were not slower than the intended ones
(walkthrough participants who pick the wrong button as fast as the right one): no time lost
is written, 0 s, and said so; a family fitted to the differences clipped at 0 wrote a cost
(its mean above 0) that the difference of means, below 0, does not show."""

from __future__ import annotations

import numpy as np
import pytest

from opspec.usermodels.choice_estimates import wrong_choice_loss
from opspec.usermodels.distributions import Constant


def test_wrong_picks_no_slower_cost_nothing() -> None:
    rng = np.random.default_rng(3)
    right = list(rng.lognormal(np.log(2.5), 0.3, 48))
    wrong = list(rng.lognormal(np.log(2.3), 0.3, 10))
    loss = wrong_choice_loss("choose", "ok", {"ok": right, "wrong": wrong}, "aic")
    assert loss is not None
    assert loss.seconds == pytest.approx(np.mean(wrong) - np.mean(right))
    assert loss.seconds < 0
    assert loss.distribution == Constant(0.0)
    assert "the wrong picks were not slower: no time lost, written as 0 s" in loss.comment()


def test_slower_wrong_picks_still_cost_their_time() -> None:
    rng = np.random.default_rng(4)
    right = list(rng.lognormal(np.log(2.0), 0.2, 200))
    wrong = list(np.array(rng.lognormal(np.log(2.0), 0.2, 60)) + 8.0)
    loss = wrong_choice_loss("choose", "ok", {"ok": right, "wrong": wrong}, "aic")
    assert loss is not None and loss.seconds == pytest.approx(8.0, abs=0.5)
    assert loss.distribution.mean == pytest.approx(8.0, abs=0.5)
    assert "written as the wrong alternative's duration" in loss.comment()
