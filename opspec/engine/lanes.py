"""The user lane of a compiled package, as the front ends need it.

``opspec run``, ``opspec evaluate``, the walkthrough and the test helpers all bind one user
performer to the names the user lane's activities are offered under, and check a user model
against the lane's manual activities and deferred choices before anything runs. This module
answers both questions once, from the compiled tables.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from opspec.engine.compiled import (
    K_GATEWAY,
    K_MANUAL,
    CompiledActivity,
    CompiledPackage,
    CTransition,
)

__all__ = ["UserLane", "all_activities", "user_lane", "user_offers"]


@dataclass(frozen=True, slots=True)
class UserLane:
    """What the user lane of a package asks of its performer.

    - ``bind_names``: participant ids (or lane names) to bind the user performer to;
    - ``manual``: ids of the manual activities offered to the user as work items, in spec
      order;
    - ``choices``: deferred-choice activity id → the ids of its alternatives. An alternative
      is *performed by the choice* (the person's pick completes it at once): it is in
      ``manual`` only when some other transition, or the start, also leads to it.
    """

    bind_names: tuple[str, ...]
    manual: tuple[str, ...]
    choices: dict[str, tuple[str, ...]]

    @property
    def empty(self) -> bool:
        return not self.manual and not self.choices


def all_activities(compiled: CompiledPackage) -> Iterator[CompiledActivity]:
    """Every compiled activity of every process, activity sets included."""
    for proc in compiled.processes.values():
        stack = [proc.graph]
        while stack:
            graph = stack.pop()
            for act in graph.activities:
                yield act
                if act.block is not None:
                    stack.append(act.block)


def _branches(act: CompiledActivity) -> tuple[CTransition, ...]:
    return act.choice or (act.out if act.kind == K_GATEWAY else ())


def _choice_branches(activities: tuple[CompiledActivity, ...]) -> set[int]:
    """Indices of the transitions that are branches of a deferred choice."""
    return {t.index for act in activities for t in _branches(act)}


def user_lane(compiled: CompiledPackage) -> UserLane:
    """The user lane of ``compiled`` (``bind_names`` is ``("user",)`` when nothing names it)."""
    names: dict[str, None] = {}
    manual: dict[str, None] = {}
    choices: dict[str, tuple[str, ...]] = {}
    for proc in compiled.processes.values():
        stack = [proc.graph]
        while stack:
            graph = stack.pop()
            chosen = _choice_branches(graph.activities)
            for act in graph.activities:
                if act.block is not None:
                    stack.append(act.block)
                if not act.user_lane:
                    continue
                name = act.participant or (act.lanes[0] if act.lanes else None)
                if name:
                    names[name] = None
                offered = act.index in graph.starts or not act.in_slots or any(
                    t not in chosen for t in act.in_slots)
                if act.kind == K_MANUAL and offered:
                    manual[act.id] = None
                # a deferred choice: an event-based gateway, or an activity whose own
                # outgoing transitions are offered as alternatives after it completes
                branches = _branches(act)
                alternatives = tuple(graph.activities[t.target].id for t in branches
                                     if graph.activities[t.target].kind == K_MANUAL)
                if alternatives:
                    choices[act.id] = alternatives
    return UserLane(tuple(names) or ("user",), tuple(manual), choices)


def user_offers(compiled: CompiledPackage) -> frozenset[str]:
    """Ids of the activities a performer bound to the user lane (:attr:`UserLane.bind_names`)
    can be offered: the manual activities and deferred choices whose participant or a lane is
    one of those names, and the choices' alternatives. A script step naming any other
    activity would never be used (``opspec.request.scripted_user`` refuses it)."""
    bound = set(user_lane(compiled).bind_names)
    out: set[str] = set()
    for proc in compiled.processes.values():
        stack = [proc.graph]
        while stack:
            graph = stack.pop()
            for act in graph.activities:
                if act.block is not None:
                    stack.append(act.block)
                if act.participant not in bound and not any(n in bound for n in act.lanes):
                    continue
                branches = _branches(act)
                if act.kind == K_MANUAL or branches or act.labelled:
                    out.add(act.id)
                out.update(graph.activities[t.target].id for t in branches)
    return frozenset(out)
