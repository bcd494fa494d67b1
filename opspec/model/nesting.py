"""How deeply a spec's embedded sub-processes (BlockActivities) may nest.

Real specs nest a few levels; the compiler and the soundness check follow blocks recursively,
so a hostile or generated spec nesting thousands deep (or blocks referring to each other in a
cycle) is refused at its line before either runs — by the front hall's gate
(:func:`opspec.request.open_gated`), so at every door, and by ``opspec validate``.
"""

from __future__ import annotations

from typing import Any

from opspec.errors import SpecError
from opspec.model.activities import BlockActivity

__all__ = ["MAX_BLOCK_NESTING", "nesting_problem"]

#: How deeply BlockActivities may nest (a block whose activity set holds a block…).
MAX_BLOCK_NESTING = 100


def nesting_problem(package: Any) -> SpecError | None:
    """A located :class:`SpecError` when a process nests BlockActivities more than
    :data:`MAX_BLOCK_NESTING` deep (found without recursion), else ``None``."""
    for process in getattr(package, "processes", ()):
        sets = {s.id: s for s in process.activity_sets}
        stack = [(a, 1) for a in process.activities]
        # the deepest each set was entered at: a set entered again no deeper is not walked
        # again, so blocks sharing sets cost at most MAX_BLOCK_NESTING walks of each set
        deepest: dict[str, int] = {}
        while stack:
            activity, depth = stack.pop()
            body = activity.body
            if not isinstance(body, BlockActivity) or body.activity_set not in sets:
                continue
            if deepest.get(body.activity_set, 0) >= depth:
                continue
            deepest[body.activity_set] = depth
            if depth > MAX_BLOCK_NESTING:
                return SpecError(
                    f"process {process.id!r}: BlockActivity {activity.id!r} is nested more "
                    f"than {MAX_BLOCK_NESTING} blocks deep (or its blocks refer to each "
                    "other in a cycle)", location=activity.location,
                    hint="flatten the embedded subprocesses, or call a subflow instead")
            stack.extend((a, depth + 1) for a in sets[body.activity_set].activities)
    return None
