"""Holm's step-down adjustment of p-values (family-wise error control).

Holm, S. (1979). A simple sequentially rejective multiple test procedure. *Scandinavian
Journal of Statistics* 6(2), 65-70. Sort the m p-values ascending; the i-th smallest
(1-based) is compared with ``level / (m - i + 1)``; rejection stops at the first that is not
below its bound. The adjusted p-value of the i-th smallest is
``max over j <= i of min(1, (m - j + 1) * p_(j))``, so "adjusted p <= level" is exactly
Holm's rejection at that level, whatever the level. It controls the probability of any
false rejection at ``level`` under any dependence between the tests — the reason it is used
here: the checks of one model on one set of people share those people.

(scipy's ``false_discovery_control`` is Benjamini-Hochberg, which controls the false
discovery *rate*, not the family-wise error.)
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["holm_adjust"]


def holm_adjust(p_values: Sequence[float]) -> list[float]:
    """Holm-adjusted p-values, in the order given."""
    m = len(p_values)
    order = sorted(range(m), key=lambda i: p_values[i])
    adjusted = [1.0] * m
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * float(p_values[i])))
        adjusted[i] = running
    return adjusted
