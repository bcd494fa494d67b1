"""The exact (Clopper-Pearson) interval from beta quantiles: the published ends, and
scipy.stats.binomtest's root-found ends, whatever the counts."""

from __future__ import annotations

import pytest
from scipy import stats

from opspec.statistics import rate_interval


@pytest.mark.parametrize(("k", "n", "low", "high"), [
    (0, 10, 0.0, 1 - 0.025 ** (1 / 10)),    # closed form at zero events: 0.3085
    (5, 10, 0.1871, 0.8129),                # the textbook table (e.g. Agresti & Coull 1998)
    (1, 10, 0.0025, 0.4450),
    (10, 10, 0.025 ** (1 / 10), 1.0),
])
def test_published_ends(k, n, low, high):
    _, lo, hi = rate_interval(k, n, 0.95, method="clopper-pearson")
    assert lo == pytest.approx(low, abs=5e-5)
    assert hi == pytest.approx(high, abs=5e-5)


def test_the_same_ends_as_binomtest():
    for n in [*range(1, 40), 100, 1000, 120_000]:
        for k in sorted({0, 1, 2, 3, n // 3, n // 2, n - 1, n} & set(range(n + 1))):
            for level in (0.9, 0.95, 0.99):
                ref = stats.binomtest(k, n).proportion_ci(confidence_level=level,
                                                          method="exact")
                _, lo, hi = rate_interval(k, n, level, method="clopper-pearson")
                assert lo == pytest.approx(ref.low, abs=1e-10), (k, n, level)
                assert hi == pytest.approx(ref.high, abs=1e-10), (k, n, level)
