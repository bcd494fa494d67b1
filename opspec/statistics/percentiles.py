"""Percentiles of a sample: the two conventions opspec uses, in one place.

* :func:`linear` — linear interpolation between order statistics (numpy's default, Hyndman &
  Fan's definition 7): the summaries' medians and p95 of durations and of per-user values;
* :func:`nearest_rank` — the smallest value with at least a share ``q`` of the sample at or
  below it (Hyndman & Fan's definition 1): a value somebody actually had, for latencies of
  hardware and for per-user targets (a user's own rate over a short run takes few values, and a
  quantile between them would describe nobody).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["interpolation_point", "linear", "nearest_rank"]


def interpolation_point(n: int, q: float) -> tuple[int, float]:
    """``(i, f)``: the ``q``-quantile of ``n`` sorted values is ``x[i] + f·(x[i+1] − x[i])``
    (0-based; ``f`` is 0 at the last value). Also used to fetch just the two values a
    quantile needs from a database, without reading the sample."""
    pos = (n - 1) * q
    lo = math.floor(pos)
    return lo, pos - lo


def linear(ordered: Sequence[float], q: float) -> float:
    """The ``q``-quantile (``q`` in [0, 1]) of the sorted ``ordered`` by linear interpolation;
    NaN when it is empty."""
    if not ordered:
        return math.nan
    lo, frac = interpolation_point(len(ordered), q)
    hi = min(lo + 1, len(ordered) - 1)
    return ordered[lo] + (ordered[hi] - ordered[lo]) * frac


def nearest_rank(ordered: Sequence[float], q: float, *, from_top: bool = False) -> float:
    """The nearest-rank ``q``-quantile of the sorted ``ordered``: the ``ceil(q·n)``-th smallest
    value (``from_top``: the ``ceil(q·n)``-th largest, the value a share ``q`` of the sample
    is at or above); NaN when it is empty."""
    if not ordered:
        return math.nan
    # 1e-9: q·n computed in floating point lands just above a whole rank (0.95 · 20)
    rank = min(len(ordered), max(1, math.ceil(q * len(ordered) - 1e-9)))
    return ordered[len(ordered) - rank] if from_top else ordered[rank - 1]
