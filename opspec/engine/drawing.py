"""Undecided gateways: the branches a spec leaves to chance, drawn (docs/bpmn.md,
Undecided gateways). Functions of :class:`~opspec.engine.flow.Flow`'s state, as in
:mod:`opspec.engine.joins`."""

from __future__ import annotations

from typing import TYPE_CHECKING

from opspec.engine.compiled import S_XOR, CompiledActivity, CTransition
from opspec.engine.instances import Frame
from opspec.engine.trace import EventKind as EK

if TYPE_CHECKING:
    from opspec.engine.flow import Flow

__all__ = ["draw", "inputs_missing"]


def inputs_missing(flow: Flow, act: CompiledActivity) -> bool:
    """Whether a run input the gateway's conditions read has no value in this run."""
    data = flow.state.package_data
    for name in act.inputs:
        if data.get(name) is None:
            return True
    return False


def draw(flow: Flow, frame: Frame, act: CompiledActivity) -> None:
    """The branches of a gateway the spec leaves undecided, drawn from the gateway's own
    seeded stream with the declared probabilities: an exclusive gateway takes one; an
    inclusive one takes each with its probability, drawn again until at least one is taken
    (so the shares given are conditional on that)."""
    rng = flow.state.streams.stream(f"branch:{act.process}:{act.id}")
    drawn = act.drawn
    picks: list[CTransition] = []
    if act.split == S_XOR:
        u = float(rng.random())
        total = 0.0
        picks.append(drawn[-1])
        for trans in drawn:
            total += trans.probability
            if u < total:
                picks[0] = trans
                break
    else:
        for _attempt in range(1000):
            picks = [t for t in drawn if float(rng.random()) < t.probability]
            if picks:
                break
        else:
            picks = [max(drawn, key=lambda t: t.probability)]
    inst = frame.inst
    for trans in picks:
        flow.state.emit_act(EK.BRANCH_CHOSEN, inst, act,
                            {"flow": trans.id, "probability": trans.probability})
        flow.take(frame, trans)
