"""What the interpreter's four parts (:class:`~opspec.engine.flow.Flow`,
:class:`~opspec.engine.activities.Activities`, :class:`~opspec.engine.triggers.Triggers`,
:class:`~opspec.engine.offers.Offers`) have in common: the run's state, and each other.

They call each other (a completed activity moves tokens, a token starts an activity, a timer
fires a trigger, an offer's answer completes an activity), so the interpreter makes all four
first and then wires them together once (:meth:`Part.connect`). Compiled with the engine
(``opspec._native.MODULES``): a compiled class can only extend a compiled one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from opspec.engine.activities import Activities
    from opspec.engine.flow import Flow
    from opspec.engine.offers import Offers
    from opspec.engine.runstate import RunState
    from opspec.engine.triggers import Triggers

__all__ = ["Part"]


class Part:
    """One part of the interpreter, over the state of one run."""

    flow: Flow
    activities: Activities
    triggers: Triggers
    offers: Offers

    def __init__(self, state: RunState) -> None:
        self.state = state

    def connect(self, flow: Flow, activities: Activities, triggers: Triggers,
                offers: Offers) -> None:
        """The other parts of the interpreter (they call each other)."""
        self.flow = flow
        self.activities = activities
        self.triggers = triggers
        self.offers = offers
