"""Trace files the fit tests write: the header, the run's start, then the events of the lane."""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any


def walks(durations: Iterable[float], activity: str = "walk", gap: float = 100.0
          ) -> list[dict[str, Any]]:
    """One offer and completion of ``activity`` on the user lane per duration, instance 1, 2,
    …, each ``gap`` seconds after the last one ended."""
    events: list[dict[str, Any]] = []
    t = 0.0
    for i, duration in enumerate(durations, start=1):
        events.append({"time": t, "kind": "activity.offered", "activity": activity,
                       "lane": "user", "instance": i})
        t += duration
        events.append({"time": t, "kind": "activity.completed", "activity": activity,
                       "lane": "user", "instance": i})
        t += gap
    return events


def write_trace(path: Path, events: Iterable[dict[str, Any]], **header: Any) -> Path:
    """``path`` as opspec writes a trace: its header (``person``, ``spec``…), ``run.started``
    at 0 and ``events``."""
    lines = [{"format": "opspec-trace", "version": 1, **header},
             {"time": 0.0, "kind": "run.started"}, *events]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path
