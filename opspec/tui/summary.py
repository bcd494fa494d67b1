"""The end of a walkthrough in words: the spec's metrics, the person's response times, where
the recording is.

The metrics are those ``opspec run`` prints for the same run (the spec's ``opspec:Metrics``:
doses taken and missed, alarms, report latency...), formatted the same way, so the numbers a
coordinator reads at the end of a session are those ``opspec run SPEC --script RECORDING``
prints. The response times are the person's own, in wall-clock seconds from the offer reaching
them to their key (:mod:`opspec.tui.timing`), with how many of them are usable for
``opspec fit``.
"""

from __future__ import annotations

import shlex
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from statistics import median

from opspec.evaluation.run_metrics_text import metric_lines
from opspec.tui.timing import Response

__all__ = ["metric_lines", "replay_commands", "response_lines"]


def response_lines(responses: Sequence[Response]) -> list[str]:
    """The person's response times per action (wall clock), and how many are usable for
    ``opspec fit`` (with the reasons the others are not)."""
    if not responses:
        return ["  (you answered nothing)"]
    per: dict[str, list[float]] = {}
    for response in responses:
        if response.wall_s is not None:
            per.setdefault(response.label, []).append(response.wall_s)
    width = max((len(label) for label in per), default=0)
    lines = [f"  {label:<{width}}  median {median(times):.1f} s, max {max(times):.1f} s, "
             f"n {len(times)}" for label, times in per.items()]
    usable = sum(1 for r in responses if r.usable)
    why = Counter(r.why for r in responses if not r.usable and r.why)
    lines.append(f"  usable for opspec fit: {usable} of {len(responses)}"
                 + (" (not: " + "; ".join(f"{n}x {reason}" for reason, n in why.most_common())
                    + ")" if why else " (the clock ran in real time)"))
    return lines


def replay_commands(spec: str | Path, record: str | Path, *, until: float | None = None
                    ) -> tuple[str, str]:
    """The two commands that replay ``record`` (quoted for a POSIX shell, so a path with
    spaces pastes as it is): in the walkthrough, and with ``opspec run``. ``until``: the
    simulated second the session was stopped at, before the end of its run: ``opspec run``
    stops there too (``--until``), so that it prints the numbers the summary shows, not
    those of a run that goes on without the person."""
    spec_q, record_q = shlex.quote(str(spec)), shlex.quote(str(record))
    stop = "" if until is None else f" --until {until!r}"
    return (f"opspec walkthrough {spec_q} --replay {record_q}",
            f"opspec run {spec_q}{stop} --script {record_q}")
