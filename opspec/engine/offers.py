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

from opspec.engine import tools
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

_ChoiceTable = tuple[tuple[CTransition, ...], tuple[tuple[CTransition, Any], ...],
                     CompiledActivity | None, tuple[str, ...]]


def _choice_table(acts: tuple[CompiledActivity, ...],
                  branches: tuple[CTransition, ...]) -> _ChoiceTable:
    """What :meth:`Offers.offer_choice` needs of ``branches``, in their order."""
    catches = tuple((trans, acts[trans.target].trigger) for trans in branches
                    if acts[trans.target].kind == K_CATCH
                    and acts[trans.target].trigger is not None)
    manual = [acts[trans.target] for trans in branches if acts[trans.target].kind == K_MANUAL]
    return (branches, catches, manual[0] if manual else None,
            tuple([target.id for target in manual]))


class Offers(Part):
    """Work items to performers and their answers (see the module docstring)."""

    def __init__(self, state: RunState) -> None:
        super().__init__(state)
        # Bound once, for the ready queue (see Flow.__init__).
        self.choose_q: Callable[[ActivityInstance, CTransition, Any], None] = self._choose
        # per deciding activity: its branches, (branch, trigger) of the catch events among
        # them, the first manual branch's activity and the manual branches' ids
        self.choices_of: dict[CompiledActivity, _ChoiceTable] = {}

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
        state = self.state
        key = ai.key
        if data is None:
            if ai.local is None:
                # a live view of the instance's data: one per instance, shared by its items
                data = inst.view
                if data is None:
                    data = inst.view = _PROXY(inst.data)
            else:
                data = _PROXY(ChainMap(ai.local, inst.data))
        item = WorkItem(key, act.process, inst.id, act.id, act.label, act.participant,
                        act.lane, state.now,
                        application if application is not None else act.application,
                        data, choices, inst.root, duration)
        ai.item = item
        ai.performer = performer
        ai.waiting = "performer"
        state.offered[key] = ai
        cached = act.flag_cache               # RunState.act_bits's cached case, in line
        if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 4:
            state.emit(EK.ACTIVITY_OFFERED, act.process, inst.id, act.id, act.lane,
                       act.participant, {"choices": list(choices)} if choices else None)
        performer.offer(item)

    def offer_choice(self, ai: ActivityInstance, branches: tuple[CTransition, ...]) -> None:
        """A deferred choice: manual branches are offered as one work item with ``choices``;
        catch-event branches race it; the first to happen wins."""
        ai.choice = branches
        ai.waiting = "choice"
        act = ai.act
        # what the branches are is fixed by the graph: worked out once per activity and
        # its branches (from source, two list comprehensions are two frames per offer)
        known = self.choices_of.get(act)
        if known is None or known[0] is not branches:
            known = self.choices_of[act] = _choice_table(ai.frame.graph.activities, branches)
        _branches, catches, manual, choices = known
        for trans, trigger in catches:
            self.triggers.wait_trigger(ai, trigger, self._choice_event, trans)
        if act.labelled:
            self._labelled_choice(ai, branches)
        elif manual is not None:
            known_performers = self.state.performers_of     # performer_for's cached case
            performer = (known_performers[manual] if manual in known_performers
                         else self.performer_for(manual))
            if performer is None:
                ai.waiting = f"performer for the choice {list(choices)}"
                return
            self.offer(ai, performer, choices, None, None)

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
        ai.state = COMPLETED                # ActivityInstance.leave(COMPLETED), in line
        ai.gen += 1
        frame = ai.frame
        running = frame.running
        key: object = ai.key                # (boxed once: see ActivityInstance.leave)
        if key in running:
            del running[key]
        if ai.cleanup:
            ai.undo_waits()
        act = ai.act
        if act.kind == K_GATEWAY and not act.choice:
            # the gateway itself completes now (its own split is the choice)
            inst = frame.inst
            if act.end_assign and not self.flow.assign(inst, act, act.end_assign):
                return
            state = self.state                # RunState.emit_act, by the cached bits
            cached = act.flag_cache
            if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 2:
                state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                           act.participant, {"choice": frame.graph.activities[trans.target].id})
        # a chosen manual branch *is* performed by the choice; a labelled one then runs
        performed = not act.labelled
        flow = self.flow
        if trans.assignments or trans.tokens != 1 or frame.graph.completion is not None:
            flow.take(frame, trans, performed=performed)
            flow.token_gone(frame)
            return
        # Flow.take and Flow.token_gone, in line: the branch's token is queued and the
        # choice's own is gone (the frame's live count is the same; it stays above 0)
        performs = flow.performs            # (empty compiled: its size, no look-up)
        state = self.state
        if performed and performs and trans in performs:
            state.ready.append((performs[trans], frame, self.activities, trans))
        else:
            state.ready.append((flow.performed_q if performed else flow.arrive_q, frame,
                                trans.target, trans))
        if frame.ors:
            state.pending[frame] = None

    def _body_done_data(self, ai: ActivityInstance, data: Mapping[str, Any]) -> None:
        inst = ai.frame.inst
        for key, value in data.items():
            self.flow.set_field(inst, ai.act, key, value)

    def performer_complete(self, item: WorkItem, data: Mapping[str, Any] | None = None,
                           choice: str | None = None) -> None:
        """A performer completed ``item`` (the session's ``complete``, bound to this)."""
        state = self.state
        if not state.inside:        # (RunState.sync: called from outside the run's callbacks)
            state.now = float(state.env.now)
        offered = state.offered
        key = item.key
        ai = offered.get(key)
        if ai is not None:
            del offered[key]
        if ai is None or ai.state != RUNNING:
            state.stale_completions += 1
            return
        ai.item = None
        act = ai.act
        if ai.choice:
            acts = ai.frame.graph.activities
            trans: CTransition | None = None
            for branch in ai.choice:
                if acts[branch.target].id == choice:
                    trans = branch
                    break
            if trans is None:
                trans = self._unchosen(ai, item, choice)
            state.ready.append((self.choose_q, ai, trans, data))
        elif act.toolchain and key in state.tool_at:
            state.ready.append((self.activities.tool_done, ai, data, None))
        else:
            if data:
                if act.params:
                    data = tools.outputs(ai, data)
            else:
                data = None
            activities = self.activities
            dones = activities.dones        # (empty compiled: its size, no look-up)
            if dones and act in dones:      # from source: body_done's steps and on, in one
                state.ready.append((dones[act], ai, activities, data))
            else:
                state.ready.append((activities.body_done_q, ai, data, None))
        if not state.draining:
            state.drain()

    def _unchosen(self, ai: ActivityInstance, item: WorkItem,
                  choice: str | None) -> CTransition:
        """The branch of an answer that named none of ``ai``'s: the one offered, if only
        one was; else the answer is refused (the item stays offered). (Apart from
        ``performer_complete``: there the generator's closure would make cells at every
        answer, from source.)"""
        acts = ai.frame.graph.activities
        if choice is None and len(item.choices) == 1:
            only: CTransition = next(t for t in ai.choice
                                     if acts[t.target].id == item.choices[0])
            return only
        key = item.key
        self.state.offered[key] = ai
        ai.item = item
        raise ExecutionError(
            f"work item {key} ({item.activity}) needs a choice among "
            f"{', '.join(item.choices)}, got {choice!r}",
            hint="call complete(item, choice=ACTIVITY_ID)", sim_time=self.state.now)

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
