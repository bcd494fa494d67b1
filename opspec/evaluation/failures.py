"""Failed replications: what makes one failed, what kind of failure it is, what to do.

A replication fails when it cannot run (an error, a dead worker), and also when it ran but
the spec went wrong in it: a run-time fault (an instance aborted, e.g. a condition that
divides by zero on a branch only some users reach) or a deadlock. Such a run's metrics are
not the spec's: the aborted instance's dose is neither taken nor missed, so counting the run
would lower a miss rate instead of failing the evaluation. Its metrics stay in the store's
``replication`` row (for a look at what the fault cost), but no estimate uses them.

The kind is the first word of the stored error (``fault: …``, ``deadlock: …``), so stores
written before kinds existed read the same way.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["DEADLOCK", "ERROR", "FAULT", "advice", "kind_of", "run_problem"]

FAULT = "fault"
DEADLOCK = "deadlock"
ERROR = "error"


def run_problem(summary: Mapping[str, Any]) -> str | None:
    """The error of a run whose summary lists run-time faults or deadlocks (the first one's
    located message, ``file:line: …``, and how many more), or None for a sound run."""
    for kind, key in ((FAULT, "faults"), (DEADLOCK, "deadlocks")):
        found: Sequence[Mapping[str, Any]] = summary.get(key) or []
        if found:
            more = len(found) - 1
            text = f"{kind}: {found[0].get('message')}"
            if more:
                text += f" (and {more} more {kind}{'s' if more > 1 else ''} in this run)"
            return text
    return None


def kind_of(error: str | None) -> str:
    """``fault``, ``deadlock`` or ``error`` (anything else: an exception, a dead worker)."""
    head = (error or "").split(":", 1)[0]
    return head if head in (FAULT, DEADLOCK) else ERROR


def advice(failures: Sequence[tuple[str, int, str]]) -> str:
    """What to do about ``failures`` (``(design, user, error)``): a spec's fault or deadlock
    comes back on ``--resume`` (the same seed, the same run), anything else may not."""
    kinds = {kind_of(e) for _, _, e in failures}
    spec = kinds & {FAULT, DEADLOCK}
    if spec and ERROR not in kinds:
        return ("a fault or deadlock of the spec (at the file:line named) comes back on "
                "--resume: fix the spec and start a new run")
    if spec:
        return ("fix the spec where a fault or deadlock is named and start a new run; the "
                "other failures may pass with `opspec evaluate --resume --out <folder>`")
    return "run again with --resume --out <folder> to complete them"
