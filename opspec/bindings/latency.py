"""Round-trip latency of device commands, kept for the run summary and the benchmarks."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from opspec.statistics.percentiles import nearest_rank

__all__ = ["LatencySummary", "summarise"]


@dataclass(frozen=True, slots=True)
class LatencySummary:
    """Statistics of round-trip times, in seconds. ``count`` 0 means no samples (all NaN)."""

    count: int
    mean: float
    p50: float
    p99: float
    max: float

    def describe(self) -> str:
        """One line in milliseconds, like ``n=1000 mean 0.11 ms p50 0.10 p99 0.25 max 0.40``."""
        if not self.count:
            return "no commands"
        return (f"n={self.count} mean {self.mean * 1e3:.3f} ms, p50 {self.p50 * 1e3:.3f} ms, "
                f"p99 {self.p99 * 1e3:.3f} ms, max {self.max * 1e3:.3f} ms")


def summarise(samples: Iterable[float]) -> LatencySummary:
    """Mean, median, 99th percentile (nearest rank) and maximum of ``samples``."""
    ordered = sorted(samples)
    if not ordered:
        nan = float("nan")
        return LatencySummary(0, nan, nan, nan, nan)
    return LatencySummary(len(ordered), sum(ordered) / len(ordered), nearest_rank(ordered, 0.5),
                          nearest_rank(ordered, 0.99), ordered[-1])
