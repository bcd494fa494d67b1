"""An interval of no width because every user gave the same value (docs/evaluation.md,
*Intervals of no width*).

A Student t interval over users is ``estimate ± t·sd/√U``: when every user's own value is the
same (3 users who all took 4 of 4 doses; every user's difference between two designs the
same), the sd is 0 and the interval is ``[v, v]``. For a value the spec fixes (doses due on a
schedule) that is true; for a value that can differ between users it only says that these few
users did not, and a reader would take it for a value known exactly. Which of the two it is
cannot be told from the numbers; what they do tell is how many users were alike, and so how
large a share of users could still give another value: with 0 of U users unlike the others,
at most ``1 − (α/2)^(1/U)`` (the exact Clopper-Pearson upper bound of 0 of U, α = 1 − level:
70.8 % at 3 users, 0.37 % at 1,000).

:func:`no_spread` describes such an interval; it is *too few users* when that bound exceeds
:data:`ALIKE_SHARE` (fewer than 368 users): the tables mark it and say so. A count does not
get the exact Poisson interval instead: a Poisson count's users would differ (its variance
is its mean), and the counts of an evaluation often cannot (doses due on a schedule) or are
bounded (doses taken, at most those due), where a Poisson interval (2.07 to 6.99 doses taken
of 4 due) would be false in the other direction.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

__all__ = ["ALIKE_SHARE", "no_spread", "unlike_share_high"]

#: A zero-width interval over users who were all alike is shown as such (too few users) unless
#: they are enough to bound the share of users who could give another value below this (1 in
#: 100 at 95 %): 368 users all alike.
ALIKE_SHARE = 0.01


def unlike_share_high(users: int, level: float = 0.95) -> float:
    """The exact (Clopper-Pearson) upper bound at ``level`` of the share of users unlike the
    others when none of ``users`` was: ``1 − ((1 − level)/2)^(1/users)``, the beta quantile
    B(1 − α/2; 1, U) in closed form."""
    return 1.0 - ((1.0 - level) / 2.0) ** (1.0 / users)


def no_spread(ci: Sequence[float | None] | None, users: int, level: float = 0.95
              ) -> dict[str, Any] | None:
    """What the summaries say of an interval ``ci`` over ``users`` users when it has no width
    (every user gave the same value): ``users``, ``share_unlike_ci95_high``
    (:func:`unlike_share_high`) and ``too_few_users`` (that bound above :data:`ALIKE_SHARE`);
    None for an interval with a width, or none."""
    if not ci or ci[0] is None or ci[1] is None or users < 2:
        return None
    low, high = float(ci[0]), float(ci[1])
    # the t interval's sd is 0 only when every user's value is the same; summed in floating
    # point it can come out a few units in the last place instead
    if not math.isclose(low, high, rel_tol=1e-12, abs_tol=0.0):
        return None
    bound = unlike_share_high(users, level)
    return {"users": users, "share_unlike_ci95_high": bound,
            "too_few_users": bound > ALIKE_SHARE}
