"""Runaway recursion of synchronous subflow calls: how deep they may nest, and the fault
that ends them (a rare path, kept out of the compiled activity code)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from opspec.engine.lifecycle import ABORTED

if TYPE_CHECKING:
    from opspec.engine.activities import Activities
    from opspec.engine.compiled import CompiledProcess
    from opspec.engine.instances import ActivityInstance

__all__ = ["MAX_CALL_DEPTH", "too_deep"]

#: Synchronous subflow calls nested deeper than this end the run's root instance with a
#: located fault: bounded recursion (a base case) runs, runaway recursion is reported.
MAX_CALL_DEPTH = 100


def too_deep(activities: Activities, ai: ActivityInstance, target: CompiledProcess) -> None:
    """``ai`` would call ``target`` past :data:`MAX_CALL_DEPTH`: abort the outermost caller
    (which ends every nested call) with the fault located at ``ai``'s activity."""
    root = ai.frame.inst
    while root.parent is not None:
        root = root.parent.frame.inst
    act = ai.act
    state = activities.state
    text = (f"{act.where()}: activity {act.id!r} of process {act.process!r} calls "
            f"{target.id!r} {MAX_CALL_DEPTH + 1} synchronous subflow calls deep at "
            f"t={state.now:.3f} s: the recursion does not reach its base case")
    state.faults.append({"time": state.now, "process": act.process,
                         "instance": ai.frame.inst.id, "activity": act.id, "message": text})
    activities.flow.end_instance(root, ABORTED, text)
