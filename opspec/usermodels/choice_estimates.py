"""What people pick at a choice, estimated from recorded picks (``opspec fit``).

An intended alternative with a commission rate when every instance ends on the same
alternative (a wrong pick is a slip the person recovers from), fixed probabilities otherwise
(:func:`choice_model`); and the time a wrong pick costs, apart from the choice's own duration
(:func:`wrong_choice_loss`, :class:`WrongChoiceLoss`), written as the wrong alternative's
duration.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np

from opspec.usermodels.distributions import Constant, Distribution
from opspec.usermodels.duration_family import fit_duration_families
from opspec.usermodels.errors import Commission

__all__ = ["WrongChoiceLoss", "choice_model", "wrong_choice_loss"]


@dataclass(frozen=True)
class WrongChoiceLoss:
    """The time a wrong pick costs, apart from the choice's own duration: the mean of the
    wrong picks' durations minus the mean of the intended picks' (Welch 95 % interval)."""

    choice: str
    alternatives: tuple[str, ...]
    wrong: int
    right: int
    seconds: float
    ci: tuple[float, float]
    distribution: Distribution

    def comment(self) -> str:
        lo, hi = self.ci
        written = ("written as the wrong alternative's duration" if self.seconds > 0 else
                   "the wrong picks were not slower: no time lost, written as 0 s")
        return (f"time lost to a wrong choice ({', '.join(self.alternatives)}): "
                f"{self.seconds:.4g} s (95 % interval [{lo:.4g}, {hi:.4g}]) = mean of "
                f"{self.wrong} wrong pick(s) - mean of {self.right} intended pick(s); "
                + written)

    def to_json(self) -> dict[str, Any]:
        return {"choice": self.choice, "alternatives": list(self.alternatives),
                "wrong_picks": self.wrong, "intended_picks": self.right,
                "seconds": self.seconds, "ci95": list(self.ci),
                "distribution": self.distribution.to_params()}


def choice_model(picks: list[list[str]]) -> dict[str, Any]:
    """The :class:`~opspec.usermodels.model.ActivityModel` fields of a choice from each
    instance's picks (in order): ``intended`` (with a ``commission`` when wrong picks came
    first) when every instance ends on the same alternative, else ``probabilities``."""
    finals = Counter(seq[-1] for seq in picks if seq)
    if len(finals) == 1:
        intended = next(iter(finals))
        wrong_counts = [sum(1 for c in seq if c != intended) for seq in picks]
        cap = max(wrong_counts)
        if cap == 0:
            return {"intended": intended}
        # Offers at which a wrong pick was still possible: the first `cap` of each instance.
        eligible = sum(min(len(seq), cap) for seq in picks)
        wrong = sum(min(w, cap) for w in wrong_counts)
        alternatives = sorted({c for seq in picks for c in seq if c != intended})
        return {"intended": intended, "commission": Commission(
            wrong / eligible, alternatives=tuple(alternatives), max_per_instance=cap,
            source=f"fitted: {wrong} wrong pick(s) in {eligible} eligible offers")}
    everything = Counter(c for seq in picks for c in seq)
    total = sum(everything.values())
    pairs = [(name, n / total) for name, n in sorted(everything.items())]
    # Make the rounded shares add up to exactly 1 for the loader's check.
    head = [(name, round(p, 6)) for name, p in pairs[:-1]]
    return {"probabilities": (*head, (pairs[-1][0], 1.0 - sum(p for _, p in head)))}


def wrong_choice_loss(choice: str, intended: str, by_pick: dict[str, list[float]],
                      criterion: str) -> WrongChoiceLoss | None:
    """Separate the time a wrong pick costs from the choice's own duration."""
    right = np.asarray(by_pick.get(intended, []), dtype=float)
    wrong_names = tuple(sorted(p for p in by_pick if p != intended))
    wrong = np.asarray([v for p in wrong_names for v in by_pick[p]], dtype=float)
    if right.size == 0 or wrong.size == 0:
        return None
    seconds = float(wrong.mean() - right.mean())
    if wrong.size >= 2 and right.size >= 2 and (wrong.std() > 0 or right.std() > 0):
        from scipy import stats  # type: ignore[import-untyped]

        test = stats.ttest_ind(wrong, right, equal_var=False)
        ci = test.confidence_interval(0.95)
        interval = (float(ci.low), float(ci.high))
    else:
        interval = (seconds, seconds)
    if seconds <= 0:
        # the wrong picks were not slower: no time lost is measured. A family fitted to the
        # differences clipped at 0 would write a cost the data do not show (its mean above 0
        # while the difference of means is below)
        dist: Distribution = Constant(0.0)
    else:
        lost = np.maximum(wrong - right.mean(), 0.0)
        dist, _, _, _ = fit_duration_families(lost.tolist(), criterion)
    return WrongChoiceLoss(choice, wrong_names, int(wrong.size), int(right.size), seconds,
                           interval, dist)
