"""Plans' code for a token reaching an activity that waits (:mod:`opspec.engine.plans`).

Where a plan's token reaches an activity that is not instantaneous, the plan hands it over
the way ``Activities.start_slow`` would, written out for what the activity is: a plain manual
activity offered (``start_slow`` and ``Offers.offer``), a deferred choice's gateway offered
(``Offers.offer_choice``), a catch event under deadlines or boundary events armed
(``Activities.activate`` and ``_body``), a synchronous subflow called (``_body``,
``Activities.inputs``, ``Flow.start_process``); anything else through those methods
themselves. :class:`WaitingCode` writes those lines for :class:`~opspec.engine.plan_writer.
Writer`, which the tests of the plans hold to the interpreter.
"""

from __future__ import annotations

from typing import Any

from opspec.engine.call_depth import MAX_CALL_DEPTH
from opspec.engine.compiled import (
    K_CATCH,
    K_COORD,
    K_GATEWAY,
    K_MANUAL,
    K_SUBFLOW,
    CompiledActivity,
    CompiledProcess,
)
from opspec.engine.conditions import constant_value
from opspec.engine.coordinating import at_once
from opspec.engine.instances import ACTIVITY_FIELDS, FRAME_FIELDS, IN_LINE, PROCESS_FIELDS
from opspec.engine.workitem import FIELDS as ITEM_FIELDS

__all__ = ["WaitingCode", "catches_itself", "chooses_itself", "made", "offers_itself"]


def made(var: str, cls: str, fields: tuple[str | tuple[str, str], ...],
         given: dict[str, str], pad: str) -> list[str]:
    """The lines that make ``var``, an object of the plan's global class ``cls``, without
    calling the class: ``object.__new__`` and ``fields`` (``opspec.engine.instances``' tables,
    the work item's ``FIELDS``) stored in ``__init__``'s order, each a parameter's value from
    ``given`` or its start (``given`` may name a start's field too: its value then). The
    compiled engine's classes cannot be made so: there, a call of ``cls`` by keywords."""
    if not IN_LINE:     # compiled classes (a test's plans under the compiled engine)
        args = ", ".join(f"{field}={given[field]}" for field in fields
                         if isinstance(field, str))
        return [f"{pad}{var} = {cls}({args})",
                *(f"{pad}{var}.{field[0]} = {given[field[0]]}" for field in fields
                  if not isinstance(field, str) and field[0] in given)]
    lines = [f"{pad}{var} = NEW({cls})"]
    for field in fields:
        if isinstance(field, str):
            lines.append(f"{pad}{var}.{field} = {given[field]}")
        else:
            name, start = field
            lines.append(f"{pad}{var}.{name} = {given.get(name, start)}")
    return lines


def offers_itself(act: CompiledActivity) -> bool:
    """Whether a plan offers ``act`` itself (``Writer.offer``): a plain manual activity
    without parameters, start assignments or a worker to wait for."""
    return (act.plain and act.kind == K_MANUAL and not act.params and not act.start_assign
            and not act.general)


def catches_itself(act: CompiledActivity) -> bool:
    """Whether a plan starts ``act`` itself (``Writer.catch``): a catch event whose only
    waits beside its trigger are deadlines and boundary events (no start trigger or
    assignments, loop, multi-instance, duration or worker)."""
    return (act.kind == K_CATCH and act.trigger is not None and not act.plain
            and act.start_trigger is None and not act.start_assign and act.loop is None
            and act.mi is None and act.cpu == 0.0 and act.cpu_sampler is None
            and act.sampler is None and not act.general)


def chooses_itself(act: CompiledActivity) -> bool:
    """Whether a plan offers ``act``'s deferred choice itself (``Writer.choice``): an
    event-based gateway whose branches are not labelled, without start assignments or a
    worker to wait for."""
    return (act.kind == K_GATEWAY and act.plain and not act.labelled and not act.general
            and not act.start_assign)


class WaitingCode:
    """The hand-over lines of a plan's :class:`~opspec.engine.plan_writer.Writer`."""

    proc: CompiledProcess
    framed: bool
    steps: int              # the zero-time steps taken so far where a hand-over is written
    acts: tuple[CompiledActivity, ...]
    names: dict[str, Any]

    def name(self, prefix: str, value: Any) -> str:
        raise NotImplementedError

    def fields(self, act: CompiledActivity) -> str:
        raise NotImplementedError

    def value(self, fn: Any, data: str) -> str:
        raise NotImplementedError

    def hand_over(self, index: int, pad: str) -> list[str]:
        """The hand-over at activity ``index`` (as in ``lone.run``): the instance gets its
        frame with the token in it (a resume plan's has one), and the token goes the
        general way from there (whether the activity is instantaneous is known here: the
        call ``start`` or ``start_slow``)."""
        a = f"A{index}"
        act = self.acts[index]
        if act.fast:
            start = [f"{pad}activities.start(frame, {a}, {self.steps}, limit)", f"{pad}return"]
        elif offers_itself(act):
            start = self.offer(act, pad)
        elif catches_itself(act):
            start = [*self.instance(act, pad), *self.catch(act, pad)]
        elif not act.plain and act.start_trigger is None:
            start = [*self.instance(act, pad), f"{pad}activities.activate(ai)", f"{pad}return"]
        elif chooses_itself(act):
            start = [*self.instance(act, pad), *self.started(act, pad), *self.choice(act, pad)]
        elif act.plain and not act.general and not act.start_assign:
            # a coordination built-in done at once needs no instance (coordinating.at_once)
            coordinates = ([f"{pad}if {self.name('F', at_once)}(activities, frame, {a}):",
                            f"{pad}    return"] if act.kind == K_COORD else [])
            start = [*coordinates, *self.instance(act, pad), *self.started(act, pad),
                     *(self.call(act, pad) if act.kind == K_SUBFLOW
                       else [f"{pad}activities._body(ai)"]), f"{pad}return"]
        else:
            start = [f"{pad}activities.start_slow(frame, {a})", f"{pad}return"]
        if self.framed:
            return start
        return [*made("frame", "FRAME", FRAME_FIELDS,
                      {"graph": "GRAPH", "inst": "inst", "owner": "None", "live": "1"}, pad),
                f"{pad}inst.frames.append(frame)", *start]

    def catch(self, act: CompiledActivity, pad: str) -> list[str]:
        """``Activities.activate`` of a catch event under deadlines or boundary events, and
        its body (``Activities._body``: the event waited for), in line."""
        a = f"A{act.index}"
        trig = act.trigger
        assert trig is not None
        out = self.started(act, pad)
        triggers = "activities.triggers"
        if act.deadlines:
            out += [f"{pad}now = state.now", f"{pad}triggers = activities.triggers"]
            triggers = "triggers"
        for seconds, synchronous, exception in act.deadlines:
            constant = constant_value(seconds)
            if constant is not None and type(constant[0]) in (int, float):
                # a constant duration: its float and the callback's argument made once, here
                delay = float(constant[0])
                out.append(f"{pad}state.later({self.name('K', delay)}, triggers.deadline_q, ai, "
                           f"{self.name('K', (synchronous, exception, delay))})")
                continue
            out += [f"{pad}try:",
                    f"{pad}    delay = float({self.value(seconds, 'inst.scope')})",
                    f"{pad}except OpspecError as error:",
                    (f"{pad}    flow.abort(inst, {a}, "
                     f"f\"deadline cannot be computed: {{error.message}}\")"),
                    f"{pad}    return",
                    (f"{pad}state.later(delay, triggers.deadline_q, ai, "
                     f"({self.name('K', synchronous)}, {self.name('K', exception)}, delay))")]
        for index in act.boundary:
            event = self.acts[index]
            if event.trigger is not None:
                out.append(f"{pad}{triggers}.wait_trigger(ai, "
                           f"{self.name('TRG', event.trigger)}, {triggers}.boundary, "
                           f"{self.name('K', index)}, persistent=True)")
        waiting = f"{trig.kind}:{trig.name}" if trig.name else trig.kind
        return [*out,
                f"{pad}if ai.state == RUNNING:",
                f"{pad}    ai.waiting = {self.name('G', waiting)}",
                (f"{pad}    {triggers}.wait_trigger(ai, {self.name('TRG', trig)}, "
                 f"{triggers}.caught_q, None)"),
                f"{pad}    if not state.draining:",
                f"{pad}        state.drain()",
                f"{pad}return"]

    def choice(self, act: CompiledActivity, pad: str) -> list[str]:
        """``Offers.offer_choice`` of a deferred choice's gateway, in line: the catch events
        among its branches wait, and its manual branches are offered as one work item
        (``Offers.offer`` with the branches' ids as its choices)."""
        a = f"A{act.index}"
        branches = act.out
        out = [f"{pad}ai.choice = {self.name('BR', branches)}",
               f"{pad}ai.waiting = \"choice\"",
               f"{pad}offers = activities.offers"]
        manual = []
        for trans in branches:
            target = self.acts[trans.target]
            if target.kind == K_CATCH and target.trigger is not None:
                out.append(f"{pad}activities.triggers.wait_trigger(ai, "
                           f"{self.name('TRG', target.trigger)}, offers._choice_event, "
                           f"{self.name('TR', trans)})")
            elif target.kind == K_MANUAL:
                manual.append(target)
        if not manual:
            return [*out, f"{pad}return"]
        m = f"A{manual[0].index}"
        self.names[m] = manual[0]
        choices = tuple(target.id for target in manual)
        ch = self.name("CH", choices)
        waiting = self.name("G", f"performer for the choice {list(choices)}")
        return [*out,
                f"{pad}known = state.performers_of",
                f"{pad}performer = known[{m}] if {m} in known else offers.performer_for({m})",
                f"{pad}if performer is None:",
                f"{pad}    ai.waiting = {waiting}",
                f"{pad}    return",
                f"{pad}view = inst.view",
                f"{pad}if view is None:",
                f"{pad}    view = inst.view = PROXY(inst.data)",
                *self.item(act, ch, pad),
                f"{pad}ai.item = item",
                f"{pad}ai.performer = performer",
                f"{pad}ai.waiting = \"performer\"",
                f"{pad}state.offered[key] = ai",
                (f"{pad}if (cached.bits if cached.key is state.flag_key "
                 f"else state.act_bits({a})) & 4:"),
                f"{pad}    state.emit(OFFERED, {self.fields(act)}, {{\"choices\": list({ch})}})",
                f"{pad}performer.offer(item)",
                f"{pad}return"]

    def call(self, act: CompiledActivity, pad: str) -> list[str]:
        """``Activities._body`` of a synchronous subflow call, in line: its actual
        parameters (``Activities.inputs``), the depth guard, the called instance started
        with ``ai`` waiting for it."""
        target = self.name("F", act.subflow)
        items = ", ".join(f"{self.name('M', formal)}: {self.name('V', fn)}(scope, now)"
                          for _mode, formal, fn, _target in act.params if fn is not None)
        return [f"{pad}now = state.now",
                f"{pad}scope = inst.scope",
                f"{pad}try:",
                f"{pad}    data = {{{items}}}",
                f"{pad}except OpspecError as error:",
                (f"{pad}    activities.fail(ai, \"parameter\", "
                 f"f\"an actual parameter failed: {{error.message}}\")"),
                f"{pad}    return",
                f"{pad}called = state.processes[{target}]",
                f"{pad}if inst.depth >= {MAX_CALL_DEPTH}:",
                f"{pad}    activities._too_deep(ai, called)",
                f"{pad}    return",
                f"{pad}ai.waiting = {self.name('G', 'subflow ')} + called.id",
                *self.launch(pad, None),
                f"{pad}ai.child = child"]

    def launch(self, pad: str, trigger: str | None) -> list[str]:
        """``Flow.start_process(called, data, ...)`` of a subflow call, in line where the
        called workflow starts with one token and has its plan: an asynchronous start
        (``trigger``: the name of its trigger's text) or a synchronous call by ``ai``;
        the instance started is ``child``."""
        sync = trigger is None
        p = f"{pad}    "
        if sync:
            making = [f"{p}priority = called.priority",
                    f"{p}if inst.priority > priority:",
                    f"{p}    priority = inst.priority",
                    *made("child", "INSTANCE", PROCESS_FIELDS, {
                        "id": "new_id", "process": "called", "data": "child_data",
                        "scope": "child_scope", "priority": "priority", "parent": "ai",
                        "root": "inst.root", "started_at": "state.now", "state": "RUNNING",
                        "trigger": "None", "depth": "inst.depth + 1",
                        "partner": "inst.partner"}, p)]
            started = "{\"trigger\": None, \"parent\": iid}"
        else:
            making = made("child", "INSTANCE", PROCESS_FIELDS, {
                "id": "new_id", "process": "called", "data": "child_data",
                "scope": "child_scope", "priority": "called.priority", "parent": "None",
                "root": "new_id", "started_at": "state.now", "state": "RUNNING",
                "trigger": str(trigger)}, p)
            started = f"{{\"trigger\": {trigger}, \"parent\": None}}"
        fallback = ("flow.start_process(called, data, parent=ai)" if sync
                    else f"flow.start_process(called, data, trigger={trigger})")
        return [f"{pad}child_plan = called.plan",
                f"{pad}if child_plan is None or called.one_start < 0:",
                f"{pad}    child = {fallback}",
                f"{pad}else:                              # (Flow.start_process's steps)",
                f"{p}child_data = called.data.copy()",
                f"{p}if data:",
                f"{p}    child_data.update(data)",
                (f"{p}child_scope = (SCOPE(child_data, state.package_data) if state.package_data"
                 f" else child_data)"),
                f"{p}state.last_id += 1",
                f"{p}new_id = state.last_id",
                *making,
                f"{p}state.live[new_id] = child",
                f"{p}state.started += 1",
                f"{p}flags = called.flag_cache        # (the called workflow's own bits)",
                (f"{p}if (flags.bits if flags.key is state.flag_key "
                 f"else state.proc_bits(called)) & 1:"),
                (f"{p}    state.emit(PROCESS_STARTED, called.id, new_id, None, called.lane, None, "
                 f"{started})"),
                (f"{p}if state.now == state.starts_at and "
                 f"state.instant_starts < state.max_instant_starts:"),
                f"{p}    state.instant_starts += 1",
                f"{p}else:",
                f"{p}    state.start_counted(child)",
                f"{p}state.ready.append((child_plan, child, activities, None))",
                f"{p}if called.deadline is not None:",
                f"{p}    DEADLINES.arm(flow, child, called.deadline)"]

    def instance(self, act: CompiledActivity, pad: str) -> list[str]:
        """``Activities.start_slow``'s first steps: ``act``'s activity instance ``ai``,
        running in the frame (a plan hands over to ``activate`` or ``_body`` after them,
        where ``start_slow`` would: an activity that waits for more than a performer and
        has no start trigger, or a plain one without start assignments or a worker)."""
        return [f"{pad}state.last_key += 1",
                f"{pad}key = state.last_key",
                *made("ai", "ACTIVITY", ACTIVITY_FIELDS,
                      {"key": "key", "act": f"A{act.index}", "frame": "frame",
                       "started_at": "state.now", "state": "RUNNING"}, pad),
                f"{pad}frame.running[key] = ai"]

    def item(self, act: CompiledActivity, choices: str, pad: str) -> list[str]:
        """``act``'s work item ``item`` for the activity instance ``ai`` (``key``), offered
        now with the instance's data ``view`` and ``choices`` (a tuple's name): what
        ``Offers.offer`` makes, without calling ``WorkItem``."""
        return made("item", "ITEM", ITEM_FIELDS, {
            "key": "key", "process": self.name("P", act.process), "instance": "iid",
            "activity": self.name("I", act.id), "label": self.name("B", act.label),
            "participant": self.name("W", act.participant), "lane": self.name("L", act.lane),
            "offered_at": "state.now", "application": self.name("APP", act.application),
            "data": "view", "choices": choices, "root_instance": "inst.root",
            "duration": "None"}, pad)

    def started(self, act: CompiledActivity, pad: str) -> list[str]:
        """A plain activity's start traced (``Activities.start_slow``); ``cached`` is left
        set for its offer."""
        a = f"A{act.index}"
        return [f"{pad}cached = {a}.flag_cache",
                (f"{pad}if (cached.bits if cached.key is state.flag_key "
                 f"else state.act_bits({a})) & 1:"),
                f"{pad}    state.emit(STARTED, {self.fields(act)})"]

    def offer(self, act: CompiledActivity, pad: str) -> list[str]:
        """``Activities.start_slow`` of a plain manual activity without parameters or start
        assignments, and its ``Offers.offer`` to the performer bound to it, in line (no
        performer: ``Activities._body``, which says what it waits for)."""
        a = f"A{act.index}"
        fields = self.fields(act)
        return [*self.instance(act, pad), *self.started(act, pad),
                f"{pad}known = state.performers_of",
                (f"{pad}performer = known[{a}] if {a} in known "
                 f"else activities.offers.performer_for({a})"),
                f"{pad}if performer is None:",
                f"{pad}    activities._body(ai)",
                f"{pad}    return",
                f"{pad}view = inst.view",
                f"{pad}if view is None:",
                f"{pad}    view = inst.view = PROXY(inst.data)",
                *self.item(act, "()", pad),
                f"{pad}ai.item = item",
                f"{pad}ai.performer = performer",
                f"{pad}ai.waiting = \"performer\"",
                f"{pad}state.offered[key] = ai",
                (f"{pad}if (cached.bits if cached.key is state.flag_key "
                 f"else state.act_bits({a})) & 4:"),
                f"{pad}    state.emit(OFFERED, {fields}, None)",
                f"{pad}performer.offer(item)",
                f"{pad}return"]
