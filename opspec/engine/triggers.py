"""What reaches an activity or a workflow from outside its flow: triggers and events.

Catch events, event-gateway branches and boundary events wait for a message, signal, timer or
rule (:meth:`Triggers.wait_trigger`); throws and raised triggers reach them
(:meth:`Triggers.broadcast`): a signal reaches every waiter, a message exactly one receiver, is
kept for a while with nobody waiting, and is lost when nobody can catch it. Deadlines and
boundary events divert an activity onto its exception path. Start and end triggers of
workflows are armed here (:meth:`Triggers.arm_process`), and mode changes switch the active
workflows (:meth:`Triggers.change_mode`), loading a mode's file when it names one."""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Mapping
from functools import partial
from typing import TYPE_CHECKING, Any, final

from opspec.engine.compiled import CompiledActivity, CompiledPackage, CompiledProcess, CTrigger
from opspec.engine.instances import ActivityInstance, ProcessInstance
from opspec.engine.lifecycle import RUNNING, SUSPENDED, TERMINATED
from opspec.engine.part import Part
from opspec.engine.runstate import RunState, discard
from opspec.engine.timers import TUPLES, Timed, occurrences
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError

if TYPE_CHECKING:
    # (a native 64-bit integer compiled; from source only an annotation: no import)
    from mypy_extensions import i64

#: Messages of one name kept with nobody waiting (per receiving instance, or for anyone).
MESSAGE_BUFFER = 100


def _undo(table: dict[Any, Any], token: int) -> Callable[[], None]:
    return lambda: discard(table, token)        # (compiled: a message wait's undoing)


class Triggers(Part):
    """Messages, signals, timers, rules, boundary events, deadlines, start/end triggers, modes."""

    # the modes each workflow belongs to (asked at every periodic start), for the modes table
    # they were read from: a mode that loads workflows replaces the table
    _members_of: object = None
    _members: dict[str, tuple[str, ...]] | None = None

    def __init__(self, state: RunState) -> None:
        super().__init__(state)
        # a catch's handler and its deadline's, bound once for the plans (see Flow.__init__)
        self.caught_q: Callable[[ActivityInstance, Any, Any], None] = self.caught
        self.deadline_q: Callable[[ActivityInstance, Any], None] = self.deadline

    def wait_trigger(self, ai: ActivityInstance, trig: CTrigger, handler: Any, arg: Any,
                      persistent: bool = False) -> None:
        """Arrange ``handler(ai, arg, data)`` when ``trig`` happens while ``ai`` waits."""
        kind = trig.kind
        if kind in ("message", "signal"):
            key = (kind, trig.name or "")
            if kind == "message" and not persistent and self.state.kept:
                kept = self._take_kept(ai.frame.inst, key)
                if kept is not None:                # it came before we waited: caught now
                    handler(ai, arg, kept[0])
                    return
            state = self.state
            table = state.waiters.get(key)
            if table is None:
                table = state.waiters[key] = {}
            state.last_key += 1                 # (RunState.next_key in line)
            token = state.last_key
            table[token] = (ai, handler, (arg, persistent, key, token))
            # its undoing (ActivityInstance.on_leave in line): from source made and called in C
            undo: Callable[[], Any] = (partial(table.pop, token, None) if TUPLES
                                       else _undo(table, token))
            if ai.cleanup is None:
                ai.cleanup = [undo]
            else:
                ai.cleanup.append(undo)
        else:       # (apart: their closures' cells would be made at every message wait)
            self._wait_other(ai, trig, handler, arg, persistent)

    def _wait_other(self, ai: ActivityInstance, trig: CTrigger, handler: Any, arg: Any,
                    persistent: bool) -> None:
        if trig.kind in ("timer", "period"):
            inst = ai.frame.inst
            every = trig.every or 0.0
            if persistent and trig.planned and every > 0.0 and trig.count != 1:
                # a boundary timer with a timeCycle: every cycle while the activity runs
                now = self.state.now
                if trig.anchored:
                    first = max(0, math.ceil((now - trig.offset) / every))
                    self._cycle(ai, trig, handler, arg, trig.offset, first, trig.count)
                else:
                    self._cycle(ai, trig, handler, arg, now, 1,
                                trig.count + 1 if trig.count >= 0 else -1)
                return
            if trig.seconds is not None:
                delay = float(trig.seconds(inst.scope, self.state.now))
            else:
                delay = trig.offset or (trig.every or 0.0)
            self.state.later(delay, lambda a, _x: handler(a, arg, None), ai)
        elif trig.kind == "rule":
            assert trig.condition is not None
            inst = ai.frame.inst
            if trig.condition(inst.scope, self.state.now):
                handler(ai, arg, None)
                return
            rkey = next(self.state.rule_keys)
            condition = trig.condition
            self.state.rules[rkey] = (lambda: condition(inst.scope, self.state.now),
                                 lambda: handler(ai, arg, None), ai)
            ai.on_leave(lambda: discard(self.state.rules, rkey))

    def _cycle(self, ai: ActivityInstance, trig: CTrigger, handler: Any, arg: Any,
               base: float, k: int, end: int) -> None:
        """Fire boundary timer ``trig`` at ``base + k * every`` and, while ``ai`` still runs
        (a non-interrupting event), at each following cycle before ``end`` (-1: no end):
        BPMN 2.0 §10.4.5, a timeCycle "R3/PT10M" fires three times, ten minutes apart."""
        if 0 <= end <= k:
            return
        every = trig.every or 0.0
        delay = base + k * every - self.state.now

        def fired(target: ActivityInstance, _unused: Any) -> None:
            handler(target, arg, None)
            if target.state == RUNNING:
                self._cycle(target, trig, handler, arg, base, k + 1, end)
        self.state.later(delay, fired, ai)

    def check_rules(self) -> None:
        for rkey, (cond, fire, ai) in list(self.state.rules.items()):
            if ai is not None and ai.state != RUNNING:
                self.state.rules.pop(rkey, None)
                continue
            try:
                holds = cond()
            except OpspecError:
                continue
            if holds and rkey in self.state.rules:
                if ai is not None:
                    self.state.rules.pop(rkey, None)
                fire()

    def caught(self, ai: ActivityInstance, _arg: Any, data: Mapping[str, Any] | None) -> None:
        activities = self.activities
        dones = activities.dones        # (empty compiled: its size, no look-up)
        act = ai.act
        known = self._known(ai, data) if data else None     # (no frame for no data)
        if dones and act in dones:      # from source: body_done's steps and on, in one
            self.state.ready.append((dones[act], ai, activities, known))
        else:
            self.state.ready.append((activities.body_done, ai, known, None))

    def _known(self, ai: ActivityInstance, data: Mapping[str, Any] | None
               ) -> Mapping[str, Any] | None:
        if not data:
            return None
        fields = ai.frame.inst.data
        return {k: v for k, v in data.items() if k in fields} or None

    def broadcast(self, kind: str, name: str, data: Mapping[str, Any] | None,
                  inst: ProcessInstance | None = None, act: CompiledActivity | None = None
                  ) -> None:
        """Raise a signal or send a message (see :meth:`_send`).

        A *signal* reaches everything waiting for it now and is not kept: catch events,
        event-gateway branches, boundary events, start and end triggers.
        """
        state = self.state
        state.raised_names.add(name)
        proc = inst.process.id if inst is not None else None
        aid = act.id if act is not None else None
        if act is not None:
            cached = act.flag_cache           # RunState.act_bits's cached case, in line
            wanted = (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 16
        else:
            wanted = state.wants_all or (EK.TRIGGER_RAISED, proc, aid) in state.wanted
        if wanted:
            self.state.emit(EK.TRIGGER_RAISED, proc, inst.id if inst else None, aid,
                      act.lane if act else None, act.participant if act else None,
                      {"trigger": kind, "name": name, **(dict(data) if data else {})})
        key = (kind, name)
        if kind == "message":
            self._send(key, data, inst, act)
            return
        table = self.state.waiters.get(key)
        if table:
            waiting = list(table.values())
            for ai, handler, (arg, persistent, _k, token) in waiting:
                if not persistent:
                    table.pop(token, None)
                if ai.state == RUNNING:
                    handler(ai, arg, data)
        for target, start in self.state.starts.get(key, ()):
            if self.is_active(target.id):
                self.flow.start_process(target, self._fields(target, data),
                                        trigger=f"{kind}:{name}", start=start)
        for target in self.state.ends.get(key, ()):
            self.terminate_all(target.id, f"end trigger {kind}:{name}")

    def _send(self, key: tuple[str, str], data: Mapping[str, Any] | None,
              inst: ProcessInstance | None, act: CompiledActivity | None) -> None:
        """A message goes to exactly one receiver (BPMN 2.0 §9.3, message flow):

        * a *reply* — thrown by an instance that a message started, named like a message
          the starting workflow catches — goes to that starting instance only: to the
          activity of it that waits for it, else it is kept until one does, and it is lost
          (``trigger.lost``) if that instance has ended;
        * any other message goes to the activity that has waited longest for it, else it
          starts the workflows whose start trigger it is, else ends those whose end
          trigger it is, else it is kept (``trigger.kept``, at most :data:`MESSAGE_BUFFER`
          per name, the oldest lost first) for the next activity that waits for it.
        """
        table = self.state.waiters.get(key)
        partner = inst.partner if inst is not None else None
        # a reply: the id of the instance it answers (None: any other message)
        answers = (partner.id if partner is not None
                   and partner.process.id in self.state.compiled.catchers.get(key, ())
                   else None)
        if table:
            # the first running waiter (of a reply, in the instance it answers) is handed
            # the message; no copy of the table: the loop ends at the first one handed it
            for token, entry in table.items():
                ai = entry[0]
                if ai.state == RUNNING and (answers is None or ai.frame.inst.root == answers):
                    _ai, handler, (arg, persistent, _key, _token) = entry
                    if not persistent:
                        table.pop(token, None)
                    handler(ai, arg, data)
                    return
        if answers is not None:
            assert partner is not None
            if partner.state in (RUNNING, SUSPENDED):
                self._keep(key, data, inst, act, partner)
            else:
                self._lose(key, inst, act, f"the instance it answers ({partner.process.id} "
                           f"#{partner.id}) has ended")
            return
        kind, name = key
        started = False
        state = self.state
        for target, start in state.starts.get(key, ()):
            if not state.compiled.modes or self.is_active(target.id):
                child = self.flow.start_process(
                    target, self._fields(target, data) if data else None,
                    trigger=f"{kind}:{name}", start=start)
                root = inst                 # the sender's root instance
                if root is not None:
                    while root.parent is not None:
                        root = root.parent.frame.inst
                child.partner = root
                started = True
        if started:
            return
        ended = False
        for target in self.state.ends.get(key, ()):
            for i in self.state.live.values():      # (a loop: no closure's cell a message)
                if i.process.id == target.id:
                    self.terminate_all(target.id, f"end trigger {kind}:{name}")
                    ended = True
                    break
        if not ended:
            self._keep(key, data, inst, act, None)

    def _keep(self, key: tuple[str, str], data: Mapping[str, Any] | None,
              inst: ProcessInstance | None, act: CompiledActivity | None,
              partner: ProcessInstance | None) -> None:
        box_key = (partner.id if partner is not None else 0, key)
        box = self.state.kept.get(box_key)
        if box is None:
            box = self.state.kept[box_key] = deque()
        if len(box) >= MESSAGE_BUFFER:
            box.popleft()
            self._lose(key, inst, act, f"more than {MESSAGE_BUFFER} {key[1]!r} messages were "
                       "kept with nobody waiting; the oldest is dropped")
        box.append((data, self.state.now))
        self._trigger_event(EK.TRIGGER_KEPT, key, inst, act, {
            "for": None if partner is None else partner.id, "kept": len(box)})

    def _take_kept(self, waiter: ProcessInstance, key: tuple[str, str]
                   ) -> tuple[Mapping[str, Any] | None, float] | None:
        """The oldest message kept for ``waiter``'s root instance, else for anyone; messages
        kept longer than the spec's ``opspec:MessageTTL`` (or the engine option
        ``message_ttl``) are lost on the way (a button pressed hours before anyone asked is not
        an answer to the next question); without either, a message waits for its catcher."""
        now = self.state.now
        ttl = self.state.config.message_ttl
        if ttl is None:        # the spec's opspec:MessageTTL, else until caught
            ttl = self.state.compiled.package.message_ttl or math.inf
        for box_key in ((waiter.root, key), (0, key)):
            box = self.state.kept.get(box_key)
            while box:
                message = box.popleft()
                if not box:
                    del self.state.kept[box_key]
                if now - message[1] <= ttl:
                    return message
                self._lose(key, None, None, f"kept {now - message[1]:g} s with nobody "
                           f"catching it (message_ttl {ttl:g} s)")
        return None

    def _lose(self, key: tuple[str, str], inst: ProcessInstance | None,
              act: CompiledActivity | None, why: str) -> None:
        self.state.lost_messages += 1
        self._trigger_event(EK.TRIGGER_LOST, key, inst, act, {"reason": why})

    def drop_kept(self, root: ProcessInstance) -> None:
        """``root`` ended: the replies kept for it can never be caught."""
        for box_key in [k for k in self.state.kept if k[0] == root.id]:
            for _message in self.state.kept.pop(box_key):
                self._lose(box_key[1], None, None, f"the instance it answers "
                           f"({root.process.id} #{root.id}) ended before catching it")

    def _trigger_event(self, kind: str, key: tuple[str, str], inst: ProcessInstance | None,
                       act: CompiledActivity | None, extra: dict[str, Any]) -> None:
        proc = inst.process.id if inst is not None else None
        aid = act.id if act is not None else None
        if self.state.wants(kind, proc, aid):
            self.state.emit(kind, proc, inst.id if inst is not None else None, aid,
                      act.lane if act else None, act.participant if act else None,
                      {"trigger": key[0], "name": key[1], **extra})

    def _fields(self, proc: CompiledProcess, data: Mapping[str, Any] | None
                ) -> dict[str, Any] | None:
        if not data:
            return None
        return {k: v for k, v in data.items() if k in proc.data} or None

    def terminate_all(self, process_id: str, reason: str) -> None:
        for inst in [i for i in self.state.live.values() if i.process.id == process_id]:
            self.flow.end_instance(inst, TERMINATED, reason)

    def is_active(self, process_id: str) -> bool:
        """Whether ``process_id`` belongs to no mode or to the current mode."""
        if not self.state.compiled.modes:
            return True
        member = self.mode_members(process_id)
        return not member or self.state.mode in member

    def mode_members(self, process_id: str) -> tuple[str, ...]:
        """The modes ``process_id`` belongs to (none: it runs in every mode), as found in
        the package's table of modes now (kept until the table is another)."""
        modes = self.state.compiled.modes
        members = self._members
        if members is None or self._members_of is not modes:
            members = self._members = {}
            self._members_of = modes
        member = members.get(process_id)
        if member is None:
            member = members[process_id] = tuple(
                m for m, procs in modes.items() if process_id in procs)
        return member

    def boundary(self, ai: ActivityInstance, index: int, data: Mapping[str, Any] | None) -> None:
        event = ai.frame.graph.activities[index]
        frame = ai.frame
        if event.interrupting:
            # the interrupted activity's token moves on to the boundary path (below)
            group = ai.mi
            self.activities.stop(ai, TERMINATED, f"boundary event {event.id!r}")
            if group is not None and ai is group.holder:
                # the whole multi-instance activity: every instance ends, one token moves on
                self.activities.mi_cancel(group, frame, f"boundary event {event.id!r}")
                frame.live += 1
            elif group is not None:
                group.members.remove(ai)
                self.activities.mi_cancel(group, frame, f"boundary event {event.id!r}")
        else:
            frame.live += 1                         # a new token beside the activity
        self.state.ready.append((self.flow.performed, frame, index, None))

    def deadline(self, ai: ActivityInstance, arg: tuple[bool, str, float]) -> None:
        synchronous, exception, delay = arg
        act = ai.act
        frame = ai.frame
        inst = frame.inst
        self.state.emit_act(EK.DEADLINE_EXPIRED, inst, act,
                       {"exception": exception, "synchronous": synchronous, "deadline": delay})
        if synchronous:
            group = ai.mi
            self.activities.stop(ai, TERMINATED, f"deadline {exception!r}")
            if group is not None and ai is group.holder:
                # the whole multi-instance activity: every instance ends, one token moves on
                self.activities.mi_cancel(group, frame, f"deadline {exception!r}")
                frame.live += 1
            self.flow.exception_flow(frame, act, exception,
                                 f"deadline of {delay:g} s expired ({exception!r})", False)
        else:
            self.flow.exception_flow(frame, act, exception, "", True)

    def change_mode(self, mode: str, act: CompiledActivity | None = None,
                    inst: ProcessInstance | None = None) -> None:
        """Switch the active workflow set: instances of workflows outside the new mode are
        terminated, their triggers ignored; workflows of the new mode are armed (loaded
        through ``mode_loader`` first when the mode names a source)."""
        source = self.state.compiled.mode_sources.get(mode)
        if source is not None and self.state.mode_loader is not None:
            loaded = self.state.mode_loader(source)
            if not isinstance(loaded, CompiledPackage):      # a Package: compile it here
                from opspec.engine.compiled import compile_package

                loaded = compile_package(loaded)
            new = {pid: p for pid, p in loaded.processes.items() if pid not in self.state.processes}
            if new:
                self.state.processes = {**self.state.processes, **new}
                # the loaded workflows belong to the mode that loaded them (on a copy: the
                # compiled package may be shared with other runs)
                self.state.compiled = dataclasses.replace(self.state.compiled, modes={
                    **self.state.compiled.modes,
                    mode: self.state.compiled.modes.get(mode, frozenset()) | frozenset(new)})
                self._select_loaded(new.values())
                for proc in new.values():
                    self.arm_process(proc)
        old = self.state.mode
        self.state.mode = mode
        for live in list(self.state.live.values()):
            if not self.is_active(live.process.id):
                self.flow.end_instance(live, TERMINATED, f"mode change {old!r} -> {mode!r}")
        if self.state.wants(EK.MODE_CHANGED, act.process if act else None, act.id if act else None):
            self.state.emit(EK.MODE_CHANGED, act.process if act else None, inst.id if inst else None,
                      act.id if act else None, act.lane if act else None, None,
                      {"from": old, "to": mode})
        for proc in self.state.processes.values():
            members = [m for m, procs in self.state.compiled.modes.items() if proc.id in procs]
            if mode in members and proc.auto_start:
                self.flow.start_process(proc, trigger=f"mode:{mode}")

    def _select_loaded(self, procs: Iterable[CompiledProcess]) -> None:
        """Extend the listeners' expanded selectors over workflows loaded at run time (the
        boot expansion only saw the boot package), so metrics, --timing and traces see their
        events. Runs once per loaded source, never on the per-event path."""
        from opspec.engine.compiled import expand_selectors_over

        procs = tuple(procs)
        if not self.state.wants_all and self.state.selectors:
            self.state.wanted = self.state.wanted | expand_selectors_over(
                procs, self.state.selectors, package_level=False)
        self.state.full = [(lst, None if selects is None else selects | expand_selectors_over(
            procs, frozenset(lst.selects), package_level=False))  # type: ignore[attr-defined]
            for lst, selects in self.state.full]
        self.state.reselect()                     # cached "nobody wants this" bits may be stale

    def arm_process(self, proc: CompiledProcess) -> None:
        """Arm the start and end triggers of ``proc`` (mode membership checked on firing)."""
        start = proc.start_trigger
        if proc.start_events:
            # several start events: each starts its own instance, with only its path
            for trig, index in proc.start_events:
                self._arm(trig, self._starter(proc, index), starts=(proc, index))
            if proc.auto_start and proc.called_starts and self.is_active(proc.id):
                self.flow.start_process(proc, trigger="auto")    # its none start events
        elif start is None:
            if proc.auto_start and self.is_active(proc.id):
                self.flow.start_process(proc, trigger="auto")
        else:
            self._arm(start, lambda trig: self._triggered_start(proc, trig), starts=(proc, -1))
        if proc.end_trigger is not None:
            self._arm(proc.end_trigger, lambda trig: self.terminate_all(
                proc.id, f"end trigger {trig}"), ends=proc)

    def _starter(self, proc: CompiledProcess, start: int) -> Callable[[str], None]:
        return lambda label: self._triggered_start(proc, label, start)

    def _triggered_start(self, proc: CompiledProcess, trigger: str, start: int = -1) -> None:
        if self.is_active(proc.id):
            self.flow.start_process(proc, trigger=trigger, start=start)

    def _arm(self, trig: CTrigger, fire: Callable[[str], None],
             ends: CompiledProcess | None = None,
             starts: tuple[CompiledProcess, int] | None = None) -> None:
        kind = trig.kind
        if kind in ("message", "signal"):
            state = self.state
            if ends is not None:
                state.ends.setdefault((kind, trig.name or ""), []).append(ends)
            elif starts is not None:
                state.starts.setdefault((kind, trig.name or ""), []).append(starts)
        elif kind in ("timer", "period"):
            _Timer(self, trig, fire, f"{kind}", starts).arm()
        elif kind == "arrival":
            self._next_arrival(trig, fire, 0, 0.0)
        elif kind == "rule":
            condition = trig.condition
            assert condition is not None
            last = {"holds": False}
            run = self.state

            def holds() -> bool:
                value = bool(condition(run.package_data, run.now))
                rising = value and not last["holds"]
                last["holds"] = value
                return rising
            key = next(self.state.rule_keys)
            self.state.rules[key] = (holds, lambda: fire("rule"), None)

    def _next_arrival(self, trig: CTrigger, fire: Callable[[str], None], made: int,
                      gap: float) -> None:
        """Arrival ``made + 1`` of a stochastic arrival process, ``gap`` seconds from now;
        the next gap is drawn when it fires, from the process's own stream, so a seed gives
        the same arrivals whatever else the run draws."""
        if 0 <= trig.count <= made:
            return
        state = self.state
        at = state.now + max(0.0, gap)
        if state.resolution > 0.0:
            at = math.ceil(at / state.resolution) * state.resolution

        def fired() -> None:
            fire("arrival")
            state.drain()
            interval = trig.interval
            assert interval is not None
            drawn = interval(state.streams.stream(f"arrivals/{trig.name}"))
            self._next_arrival(trig, fire, made + 1, drawn)
        state.timer(max(0.0, at - state.now), fired)


@final
class _Timer(Timed):
    """A start or end timer of a workflow: fires at each of its trigger's times (starts the
    workflow, or calls ``fire(label)``), drains the work that queued and arms itself for the
    next time. One object for all the firings of a workflow, and itself the run's timed
    callback (what ``RunState.timer`` does: counted in ``sim_events``, no ``_CallAt``); a
    period's times are counted here (``timers.occurrences``' arithmetic) instead of resuming a
    generator, and a start is a direct call, not one through a closure: a robot spec's
    5 Hz workflows fire 18,000 times an hour each (docs/engine-performance.md)."""

    def __init__(self, triggers: Triggers, trig: CTrigger, fire: Callable[[str], None],
                 label: str, starts: tuple[CompiledProcess, int] | None) -> None:
        self.triggers = triggers
        self.fire = fire
        self.label = label
        self.proc: CompiledProcess | None = None
        self.start = -1
        # the modes its workflow belongs to (Triggers.mode_members), and the table of
        # modes they were found in: a firing tests the mode without a call of is_active
        self.modes: object = None
        self.member: tuple[str, ...] = ()
        # the mode last tested (the very object) and whether the workflow runs in it: the
        # mode changes seldom, so a firing mostly tests one identity, not the tuple
        self.mode: object = None
        self.runs = True
        if starts is not None:
            self.proc, self.start = starts
        now = triggers.state.now
        every = trig.every or 0.0
        # a period with no end or ``count`` firings at offset + k * every (timers.occurrences)
        self.periodic = trig.kind == "period" and every > 0
        self.times: Iterator[float] | None = None if self.periodic else occurrences(trig, now)
        self.offset = trig.offset
        self.every = every
        # (i64: a firing's count and test in machine integers compiled)
        self.count: i64 = trig.count
        self.k: i64 = max(0, math.ceil((now - trig.offset) / every)) if self.periodic else 0

    def arm(self) -> None:
        times = self.times
        if times is None:
            k = self.k
            if 0 <= self.count <= k:
                return
            at = self.offset + float(k) * self.every   # (k * every: the same float)
            self.k = k + 1
        else:
            following = next(times, None)
            if following is None:
                return
            at = following
        state = self.triggers.state
        if state.resolution > 0.0:
            at = math.ceil(at / state.resolution) * state.resolution
        delay = at - state.now
        state.sim_events += 1                   # RunState.timer
        state.schedule_timed(delay if delay > 0.0 else 0.0, self)  # noqa: FURB136

    def go(self) -> None:
        proc = self.proc
        triggers = self.triggers
        state = triggers.state
        if proc is not None:
            # Triggers._triggered_start, the workflow's modes kept here
            modes = state.compiled.modes
            mode = state.mode
            if modes is not self.modes or mode is not self.mode:
                if modes is not self.modes:
                    self.member = triggers.mode_members(proc.id)
                    self.modes = modes
                member = self.member
                self.runs = not member or mode in member
                self.mode = mode
            if self.runs:
                triggers.flow.start_process(proc, trigger=self.label, start=self.start)
        else:
            self.fire(self.label)
        state.drain()
        self.arm()

    def __call__(self, _event: Any) -> None:
        self.triggers.state.go_now(self)
