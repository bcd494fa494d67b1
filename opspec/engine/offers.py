"""Work items offered to performers, and what the performers answer.

An activity performed by someone (a manual activity, a task bound to an application, a tool,
a deferred or labelled choice) becomes a :class:`~opspec.engine.performers.WorkItem` offered to
the performer bound to its participant or lane (:meth:`Offers.offer`); the performer answers
through its session: complete (with data, or the branch chosen), omit, or fail. Answers to
items that were withdrawn meanwhile are counted as stale and otherwise ignored."""

from __future__ import annotations

from collections import ChainMap
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Final

from opspec.engine.compiled import (
    K_CATCH,
    K_GATEWAY,
    K_MANUAL,
    CompiledActivity,
    CTransition,
)
from opspec.engine.instances import ActivityInstance
from opspec.engine.lifecycle import (
    COMPLETED,
    RUNNING,
    TERMINATED,
)
from opspec.engine.part import Part
from opspec.engine.performers import Performer, WorkItem
from opspec.engine.trace import EventKind as EK
from opspec.errors import ExecutionError

if TYPE_CHECKING:
    from opspec.engine.runstate import RunState

# Final: a module static in the compiled engine, where a plain global is a dictionary lookup
_PROXY: Final = MappingProxyType


class Offers(Part):
    """Work items to performers and their answers (see the module docstring)."""

    def __init__(self, state: RunState) -> None:
        super().__init__(state)
        # Bound once, for the ready queue (see Flow.__init__).
        self.choose_q: Callable[[ActivityInstance, CTransition, Any], None] = self._choose

    def performer_for(self, act: CompiledActivity) -> Performer | None:
        known = self.state.performers_of
        # ``in`` and an index, no ``cast``: from source a call each
        if act in known:
            return known[act]
        performer = self.state.registry.lookup(act.participant, act.lanes)
        if performer is None and not act.user_lane:
            performer = self.state.registry.default_device
        known[act] = performer
        return performer

    def offer(self, ai: ActivityInstance, performer: Performer, choices: tuple[str, ...],
               data: Mapping[str, Any] | None, duration: float | None,
               application: str | None = None) -> None:
        act = ai.act
        inst = ai.frame.inst
        item = WorkItem(ai.key, act.process, inst.id, act.id, act.label, act.participant,
                        act.lane, self.state.now,
                        application if application is not None else act.application,
                        data if data is not None else _PROXY(
                            inst.data if ai.local is None else ChainMap(ai.local, inst.data)),
                        choices,
                        inst.root, duration)
        ai.item = item
        ai.performer = performer
        ai.waiting = "performer"
        self.state.offered[ai.key] = ai
        cached = act.flag_cache               # RunState.act_bits's cached case, in line
        if (cached.bits if cached.key is self.state.flag_key else self.state.act_bits(act)) & 4:
            self.state.emit(EK.ACTIVITY_OFFERED, act.process, inst.id, act.id, act.lane,
                      act.participant, {"choices": list(choices)} if choices else None)
        performer.offer(item)

    def offer_choice(self, ai: ActivityInstance, branches: tuple[CTransition, ...]) -> None:
        """A deferred choice: manual branches are offered as one work item with ``choices``;
        catch-event branches race it; the first to happen wins."""
        acts = ai.frame.graph.activities
        ai.choice = branches
        ai.waiting = "choice"
        manual = [t for t in branches if acts[t.target].kind == K_MANUAL]
        for trans in branches:
            target = acts[trans.target]
            if target.kind == K_CATCH and target.trigger is not None:
                self.triggers.wait_trigger(ai, target.trigger, self._choice_event, trans)
        if ai.act.labelled:
            self._labelled_choice(ai, branches)
        elif manual:
            performer = self.performer_for(acts[manual[0].target])
            if performer is None:
                ai.waiting = f"performer for the choice {[acts[t.target].id for t in manual]}"
                return
            # (a list, not a generator: from source a generator resumes once per item)
            self.offer(ai, performer, tuple([acts[t.target].id for t in manual]), None, None)

    def _labelled_choice(self, ai: ActivityInstance, branches: tuple[CTransition, ...]) -> None:
        """A split between labelled branches: the performer bound to the deciding activity
        (a person, a script, a user model) picks one; with nobody bound, the branch is drawn
        uniformly from the activity's random stream (reproducible for a seed)."""
        act = ai.act
        acts = ai.frame.graph.activities
        performer = self.state.registry.lookup(act.participant, act.lanes)
        if performer is not None:
            self.offer(ai, performer, tuple(acts[t.target].id for t in branches), None, None)
            return
        rng = self.state.streams.stream(f"{act.process}/{act.id}")
        self.state.ready.append((self.choose_q, ai, branches[int(rng.integers(len(branches)))],
                            None))

    def _choice_event(self, ai: ActivityInstance, trans: CTransition,
                      data: Mapping[str, Any] | None) -> None:
        self.state.ready.append((self.choose_q, ai, trans, data))

    def _choose(self, ai: ActivityInstance, trans: CTransition,
                data: Mapping[str, Any] | None) -> None:
        if ai.state != RUNNING:
            return
        if data:
            self._body_done_data(ai, data)
        item = ai.item
        if item is not None:
            ai.item = None
            offered = self.state.offered
            if item.key in offered:
                del offered[item.key]
            if ai.performer is not None:
                ai.performer.withdraw(item, "another branch of the choice happened")
        ai.leave(COMPLETED)
        frame = ai.frame
        act = ai.act
        if act.kind == K_GATEWAY and not act.choice:
            # the gateway itself completes now (its own split is the choice)
            inst = frame.inst
            if act.end_assign and not self.flow.assign(inst, act, act.end_assign):
                return
            self.state.emit_act(EK.ACTIVITY_COMPLETED, inst, act, {"choice": frame.graph.activities[
                trans.target].id})
        # a chosen manual branch *is* performed by the choice; a labelled one then runs
        self.flow.take(frame, trans, performed=not act.labelled)
        self.flow.token_gone(frame)

    def _body_done_data(self, ai: ActivityInstance, data: Mapping[str, Any]) -> None:
        inst = ai.frame.inst
        for key, value in data.items():
            self.flow.set_field(inst, ai.act, key, value)

    def performer_complete(self, item: WorkItem, data: Mapping[str, Any] | None,
                           choice: str | None) -> None:
        offered = self.state.offered
        ai = offered.get(item.key)
        if ai is not None:
            del offered[item.key]
        if ai is None or ai.state != RUNNING:
            self.state.stale_completions += 1
            return
        ai.item = None
        if ai.choice:
            acts = ai.frame.graph.activities
            trans: CTransition | None = None
            for branch in ai.choice:
                if acts[branch.target].id == choice:
                    trans = branch
                    break
            if trans is None:
                if choice is None and len(item.choices) == 1:
                    trans = next(t for t in ai.choice if acts[t.target].id == item.choices[0])
                else:
                    self.state.offered[item.key] = ai
                    ai.item = item
                    raise ExecutionError(
                        f"work item {item.key} ({item.activity}) needs a choice among "
                        f"{', '.join(item.choices)}, got {choice!r}",
                        hint="call complete(item, choice=ACTIVITY_ID)", sim_time=self.state.now)
            self.state.ready.append((self.choose_q, ai, trans, data))
        elif ai.act.toolchain and ai.key in self.state.tool_at:
            self.state.ready.append((self.activities.tool_done, ai, data, None))
        elif data:
            if ai.act.params:
                data = self.activities.outputs(ai, data)
            self.state.ready.append((self.activities.body_done_q, ai, data, None))
        else:
            self.state.ready.append((self.activities.body_done_q, ai, None, None))
        if not self.state.draining:
            self.state.drain()

    def performer_omit(self, item: WorkItem, reason: str) -> None:
        offered = self.state.offered
        ai = offered.get(item.key)
        if ai is not None:
            del offered[item.key]
        if ai is None or ai.state != RUNNING:
            self.state.stale_completions += 1
            return
        ai.item = None
        frame = ai.frame
        self.activities.stop(ai, TERMINATED, reason or "omitted")
        self.state.emit_act(EK.ACTIVITY_OMITTED, frame.inst, ai.act, {"reason": reason})
        self.flow.token_gone(frame)
        self.state.drain()

    def performer_fail(self, item: WorkItem, exception: str, message: str) -> None:
        offered = self.state.offered
        ai = offered.get(item.key)
        if ai is not None:
            del offered[item.key]
        if ai is None or ai.state != RUNNING:
            self.state.stale_completions += 1
            return
        ai.item = None
        self.activities.fail(ai, exception, message)
        self.state.drain()
