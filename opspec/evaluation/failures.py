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

from collections.abc import Sequence

# what makes a run's metrics not the spec's is decided once, for every door
from opspec.runs import run_problem

__all__ = ["DEADLOCK", "ERROR", "FAULT", "advice", "kind_of", "run_problem"]

FAULT = "fault"
DEADLOCK = "deadlock"
ERROR = "error"


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
