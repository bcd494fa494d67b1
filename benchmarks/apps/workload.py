"""The work both variants of the Table-3 benchmark do: the same functions, called the same
number of times at the same simulated times. Only the orchestration differs."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

PERIOD = 0.1          # seconds between activations (10 Hz)


def work(_data: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """A sensor-processing step: a small filter over a buffer (about 10 us of CPU)."""
    acc = 0
    for i in range(200):
        acc = (acc * 31 + i) & 0xFFFF
    return {"result": acc}


STEPS = {"straight": ("read", "filter", "decide", "plan", "act"),     # one after another
         "splitjoin": ("read", "left", "centre", "right", "fuse")}   # 3 in parallel, fused
