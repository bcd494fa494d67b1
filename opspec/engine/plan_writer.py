"""The source of a plan (:mod:`opspec.engine.plans`), written activity by activity.

:class:`Writer` writes what the interpreter does with a token, one block of lines per
activity with its successor's after it: the zero-time step count, the trace events, the
assignments, the conditions of a split called in order, a thrown or raised trigger, the
token's end and the instance's (``Flow.instance_done``); at an activity that waits, the
hand-over :class:`~opspec.engine.plan_waits.WaitingCode` writes. :func:`by_selection` then
reads the listeners' bits from the plan's globals, set once for the run's selection.
"""

from __future__ import annotations

import re
from types import MappingProxyType
from typing import Any, Final

from opspec.engine import lone, process_deadlines
from opspec.engine.compiled import (
    K_ASYNC,
    K_TASK,
    K_THROW,
    S_XOR,
    CompiledActivity,
    CompiledProcess,
    CTrigger,
)
from opspec.engine.conditions import constant_value
from opspec.engine.instances import ActivityInstance, Frame, ProcessInstance
from opspec.engine.lifecycle import COMPLETED, LIFECYCLE, RUNNING, SUSPENDED
from opspec.engine.performers import WorkItem
from opspec.engine.plan_waits import WaitingCode
from opspec.engine.scope import Scope
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError
from opspec.model import ParameterMode

__all__ = ["ENDED", "MAX_BLOCKS", "NO_TRANSITION", "Writer", "by_selection", "thrown_on",
           "ways_out"]

#: Activity blocks written out per plan at most (merging branches are written once per
#: path); past it, or deeper than :data:`_MAX_DEPTH` nested splits, the plan ends in
#: ``lone.run``.
MAX_BLOCKS: Final = 64
_MAX_DEPTH: Final = 24

#: a completed instance's state (``Flow.instance_done``'s)
ENDED: Final = LIFECYCLE.table[(RUNNING, "complete")]

NO_TRANSITION: Final = ("no outgoing transition can be taken (no condition holds and "
                        "there is no OTHERWISE transition)")


def thrown_on(act: CompiledActivity, acts: tuple[CompiledActivity, ...]) -> bool:
    """Whether ``act``, not ``lone`` for a throw or a raised trigger only, is written out
    in a resume plan: in the instance's frame, ``Activities.start`` carries the token
    through it as through a lone one, with ``Flow.done_next``'s broadcasts (an error,
    escalation or terminate, a join or several tokens ahead: the interpreter takes it)."""
    if not act.fast or act.terminate or act.error is not None or act.escalation is not None:
        return False
    if act.next < 0 and not (act.out or act.otherwise or act.choice or act.drawn):
        return True                         # an end
    return bool(ways_out(act, acts))


def ways_out(act: CompiledActivity, acts: tuple[CompiledActivity, ...]) -> list[int]:
    """Where ``act``'s token goes on completion when that is decided without a join or a
    second token (``Flow.split``'s first two cases); empty otherwise."""
    if act.next >= 0:
        return [] if acts[act.next].join else [act.next]
    if act.choice or act.drawn or act.split != S_XOR or not (act.out or act.otherwise):
        return []
    branches = act.out + act.otherwise
    if any(acts[t.target].join or t.tokens != 1 for t in branches):
        return []
    return [t.target for t in branches]


_CACHED: Final = re.compile(r"\n *cached = \w+\.flag_cache(?=\n)")
_BITS: Final = re.compile(
    r"\(cached\.bits if cached\.key is state\.flag_key else state\.(act|proc)_bits\((\w+)\)\)"
    r" & (\d+)")


def by_selection(source: str, space: dict[str, Any]) -> str:
    """``source`` with each test of an activity's or workflow's listener bits, ``(its
    bits) & 2``, read from a global of the plan (``BITS_A3_2``: whether that bit is set)
    instead of from its cache (``RunState.act_bits``'s cached case: the cache, its key and
    the run's key read, the mask taken and the int tested at every event a plan might
    trace).

    The plan tests once, where it starts, that its globals hold the bits of this run's
    listener selection (``KEY``, the run's ``flag_key``) and has ``SELECT`` set them for it
    if not (another run of the package, a new selection). A selection changes within a run
    only when a mode loads workflows (``Triggers.change_mode``), which adds selectors of the
    loaded workflows alone: the bits of the activities a plan writes out stay what they were
    (and the plan's next start sees the new key and selects again)."""
    source = _CACHED.sub("", source)
    wanted: dict[str, tuple[Any, bool, int]] = {}

    def named(found: re.Match[str]) -> str:
        kind, obj, mask = found.group(1), found.group(2), found.group(3)
        global_name = f"BITS_{obj}_{mask}"
        wanted[global_name] = (space[obj], kind == "proc", int(mask))
        return global_name

    source = _BITS.sub(named, source)
    entries = tuple((global_name, obj, is_proc, mask)
                    for global_name, (obj, is_proc, mask) in wanted.items())

    def select(state: Any) -> None:
        for global_name, obj, is_proc, mask in entries:
            bits = state.proc_bits(obj) if is_proc else state.act_bits(obj)
            space[global_name] = (bits & mask) != 0     # (a bool: tested without a call)
        space["KEY"] = state.flag_key

    space["KEY"] = None                     # (no run's key: the first start selects)
    space["SELECT"] = select
    return source


class Writer(WaitingCode):
    """Writes one plan's source: a block per activity, the successor's after it."""

    def __init__(self, proc: CompiledProcess, framed: bool) -> None:
        self.proc = proc
        # in the instance's frame (a resume plan: ``Activities.start``'s steps) or before
        # it has one (the first token: ``lone.run``'s)
        self.framed = framed
        self.acts = proc.graph.activities
        self.blocks = 0
        self.steps = 0                      # (see block)
        self.uncounted = 0                  # (1: the first block is a performed branch's)
        # the plan's globals: what its source names (activities, conditions, helpers)
        self.names: dict[str, Any] = {
            "__builtins__": __builtins__, "REST": lone.run,
            "FRAME": Frame, "GRAPH": proc.graph,
            "OpspecError": OpspecError, "RUNNING": RUNNING, "SUSPENDED": SUSPENDED,
            "STARTED": EK.ACTIVITY_STARTED, "COMPLETED": EK.ACTIVITY_COMPLETED,
            "CHANGED": EK.DATA_CHANGED, "OFFERED": EK.ACTIVITY_OFFERED, "DONE": COMPLETED,
            "ACTIVITY": ActivityInstance, "ITEM": WorkItem, "PROXY": MappingProxyType,
            "ENDED": ENDED, "ENDED_KIND": EK.PROCESS_COMPLETED, "IN": ParameterMode.IN,
            "INSTANCE": ProcessInstance, "SCOPE": Scope, "DEADLINES": process_deadlines,
            "PROCESS_STARTED": EK.PROCESS_STARTED, "NEW": object.__new__}

    def name(self, prefix: str, value: Any) -> str:
        key = f"{prefix}{len(self.names)}"
        self.names[key] = value
        return key

    def block(self, index: int, path: tuple[int, ...], depth: int, out: list[str],
              performed: bool = False) -> None:
        """The code of the token at activity ``index`` (reached through ``path``;
        ``performed``: the branch a deferred choice took, which starts and completes at
        once without a step of its own, as ``Flow.performed`` runs it)."""
        pad = "    " * depth
        act = self.acts[index]
        a = f"A{index}"
        self.names[a] = act
        self.blocks += 1
        # the token's zero-time steps so far, a constant of the plan: a block on its path each
        steps = self.steps = len(path) - self.uncounted     # (but a performed branch's)
        self.uncounted |= performed
        if not performed:
            if index in path or self.blocks > MAX_BLOCKS or depth > _MAX_DEPTH:
                out.append(f"{pad}activities.start(frame, {a}, {steps}, limit)" if self.framed
                           else f"{pad}REST(activities, inst, {a}, {steps}, limit)")
                out.append(f"{pad}return")
                return
            if not (act.lone or self.framed and thrown_on(act, self.acts)):
                out.extend(self.hand_over(index, pad))
                return
            waits = []                      # lone, but not on this run
            if act.general:
                waits.append("pooled")
            if act.kind == K_TASK:
                waits.append(f"{self.name('APP', act.application)} in apps")
            if waits:
                out.append(f"{pad}if {' or '.join(waits)}:")
                out.extend(self.hand_over(index, pad + "    "))
            out += [f"{pad}if {steps + 1} > limit:",
                    f"{pad}    state.zero_time({'frame' if self.framed else 'inst'}, {a})"]
        fields = self.fields(act)
        out += [f"{pad}cached = {a}.flag_cache",
                f"{pad}if (cached.bits if cached.key is state.flag_key "
                f"else state.act_bits({a})) & 1:",
                f"{pad}    state.emit(STARTED, {fields})"]
        if act.simple_end and not act.start_assign and act.kind != K_ASYNC:
            out += [f"{pad}if (cached.bits if cached.key is state.flag_key "
                    f"else state.act_bits({a})) & 2:",
                    f"{pad}    state.emit(COMPLETED, {fields})"]
        else:
            if act.start_assign:
                self.assign(act, act.start_assign, pad, out)
            if act.kind == K_ASYNC:
                # Activities.params_in, in line: the actual parameters in order, into a dict
                items = ", ".join(f"{self.name('M', formal)}: {self.name('V', fn)}(scope, now)"
                                  for _mode, formal, fn, _target in act.params
                                  if fn is not None)
                out += [f"{pad}now = state.now", f"{pad}scope = inst.scope", f"{pad}try:",
                        f"{pad}    data = {{{items}}}",
                        f"{pad}except OpspecError as error:",
                        f"{pad}    flow.abort(inst, {a}, "
                        f"f\"an actual parameter failed: {{error.message}}\")",
                        f"{pad}    return",
                        f"{pad}called = state.processes[{self.name('F', act.subflow)}]",
                        *self.launch(pad, self.name("G", f"subflow:{act.id}"))]
            if not act.simple_end and act.end_assign:
                self.assign(act, act.end_assign, pad, out)
            if act.kind == K_THROW and act.trigger is not None:     # (Flow.done_next's)
                out.append(f"{pad}flow.triggers.broadcast({self.trigger(act.trigger)}, "
                           f"None, inst, {a})")
            out += [f"{pad}cached = {a}.flag_cache",
                    f"{pad}if (cached.bits if cached.key is state.flag_key "
                    f"else state.act_bits({a})) & 2:",
                    f"{pad}    state.emit(COMPLETED, {fields})"]
            if act.raises is not None:
                out += [f"{pad}if inst.state == RUNNING:",
                        (f"{pad}    flow.triggers.broadcast({self.trigger(act.raises)}, "
                         f"None, inst, {a})")]
            if not act.simple_end:
                out += [f"{pad}if inst.state != RUNNING:", f"{pad}    return"]
        path = (*path, index)
        if act.next >= 0:
            self.block(act.next, path, depth, out)
        elif act.out or act.otherwise:
            self.split(index, path, depth, out)
        else:                               # an end: the token is gone
            out += self.gone(pad)
            out.append(f"{pad}return")

    def trigger(self, trig: CTrigger) -> str:
        """A thrown or raised trigger's kind and name, as ``Triggers.broadcast`` takes them."""
        return f"{self.name('G', trig.kind)}, {self.name('G', trig.name or '')}"

    def fields(self, act: CompiledActivity) -> str:
        """The arguments of ``act``'s trace events after their kind."""
        return (f"{self.name('P', act.process)}, iid, {self.name('I', act.id)}, "
                f"{self.name('L', act.lane)}, {self.name('W', act.participant)}")

    def gone(self, pad: str) -> list[str]:
        """The token ends: the frameless instance is done, or the frame loses a token
        (``Flow.split``'s end, ``Flow.token_gone``: in line, as the instance's top frame is
        never an activity set's, when the workflow is no ad-hoc set)."""
        if not self.framed:
            return self.done(pad)
        if self.proc.graph.completion is not None:
            return [f"{pad}flow.token_gone(frame)"]
        return [f"{pad}frame.live -= 1",
                f"{pad}if frame.live <= 0 or frame.ors:",
                f"{pad}    if frame.live <= 0 and not frame.parked:",
                *self.done(pad + "        "),
                f"{pad}    else:",
                f"{pad}        state.pending[frame] = None"]

    def done(self, pad: str) -> list[str]:
        """``Flow.instance_done(inst)``, in line: the instance completes, and a synchronous
        caller gets its OUT parameters (a frameless instance has no frames to clear)."""
        proc = self.proc
        p = self.name("PR", proc)
        return [f"{pad}if inst.state == RUNNING:          # (Flow.instance_done's steps)",
                f"{pad}    inst.state = ENDED",
                *([f"{pad}    inst.frames.clear()"] if self.framed else []),
                f"{pad}    live = state.live",
                f"{pad}    if iid in live:",
                f"{pad}        del live[iid]",
                f"{pad}    parent = inst.parent",
                f"{pad}    if state.kept and parent is None:",
                f"{pad}        flow.triggers.drop_kept(inst)",
                f"{pad}    state.completed += 1",
                f"{pad}    cached = {p}.flag_cache",
                (f"{pad}    if (cached.bits if cached.key is state.flag_key "
                 f"else state.proc_bits({p})) & 2:"),
                (f"{pad}        state.emit(ENDED_KIND, {self.name('P', proc.id)}, iid, None, "
                 f"{self.name('L', proc.lane)}, None, "
                 f"{{\"duration\": state.now - inst.started_at}})"),
                f"{pad}    if parent is not None and parent.state == RUNNING:",
                f"{pad}        parent.child = None",
                f"{pad}        out = {{}}",
                f"{pad}        for mode, formal, _fn, target in parent.act.params:",
                f"{pad}            if mode is not IN and target is not None:",
                f"{pad}                out[target] = inst.data.get(formal)",
                # (body_done's first step: the caller's done plan, if it has one)
                f"{pad}        dones = activities.dones",
                f"{pad}        if parent.act in dones:",
                f"{pad}            dones[parent.act](parent, activities, out or None)",
                f"{pad}        else:",
                f"{pad}            activities.body_done(parent, out or None)"]

    def split(self, index: int, path: tuple[int, ...], depth: int, out: list[str]) -> None:
        """``lone.xor_transition`` of activity ``index``, then the chosen target's code."""
        pad = "    " * depth
        act = self.acts[index]
        a = f"A{index}"
        out += [f"{pad}scope = inst.scope", f"{pad}now = state.now", f"{pad}try:"]
        taken = list(act.out)
        chain: list[str] = []
        closed = False                      # a transition without a condition: always taken
        for k, trans in enumerate(taken):
            if trans.condition is None:
                chain += ([f"{pad}    else:", f"{pad}        k = {k}"] if chain
                          else [f"{pad}    k = {k}"])
                closed = True
                break
            test = f"{self.name('C', trans.condition)}(scope, now)"
            chain += [f"{pad}    {'elif' if chain else 'if'} {test}:", f"{pad}        k = {k}"]
        if not closed:
            inner = f"{pad}        " if chain else f"{pad}    "
            if chain:
                chain.append(f"{pad}    else:")
            if act.otherwise:
                taken.append(act.otherwise[0])
                chain.append(f"{inner}k = {len(taken) - 1}")
            elif act.path_may_end:          # no condition holds: this path ends
                chain += [*self.gone(inner), f"{inner}k = -1"]
            else:
                chain += [f"{inner}flow.abort(inst, {a}, {NO_TRANSITION!r})", f"{inner}k = -1"]
        out += chain
        out += [f"{pad}except OpspecError as error:",
                f"{pad}    flow.abort(inst, {a}, "
                f"f\"a transition condition failed: {{error.message}}\")",
                f"{pad}    return"]
        for k, trans in enumerate(taken):
            out.append(f"{pad}{'if' if k == 0 else 'elif'} k == {k}:")
            for target_name, fn in trans.assignments:
                # Flow.set_field(inst, None, ...), in line
                out.append(f"{pad}    value = {self.value(fn, 'scope')}")
                self.set_field(None, target_name, pad + "    ", out)
            self.block(trans.target, path, depth + 1, out)
        out += [f"{pad}return"]

    def assign(self, act: CompiledActivity, assignments: tuple[tuple[str, Any], ...],
               pad: str, out: list[str]) -> None:
        """``Flow.assign(inst, act, assignments)``, in line (a failed one aborts the
        instance; the token stops where the instance no longer runs)."""
        a = f"A{act.index}"
        self.names[a] = act
        out += [f"{pad}now = state.now", f"{pad}reads = inst.scope", f"{pad}try:"]
        for target, fn in assignments:
            out.append(f"{pad}    value = {self.value(fn, 'reads')}")
            self.set_field(act, target, pad + "    ", out)
            out += [f"{pad}    if inst.state != RUNNING:", f"{pad}        return"]
        out += [f"{pad}except OpspecError as error:",
                f"{pad}    flow.abort(inst, {a}, f\"an assignment failed: {{error.message}}\")",
                f"{pad}    return"]

    def value(self, fn: Any, data: str) -> str:
        """The call of the expression ``fn`` over ``data``, or its value where it is a
        constant (bound by name, as every value of the spec)."""
        constant = constant_value(fn)
        if constant is not None:
            return self.name("K", constant[0])
        return f"{self.name('V', fn)}({data}, now)"

    def set_field(self, act: CompiledActivity | None, target: str, pad: str,
                  out: list[str], named: bool = False) -> None:
        """``Flow.set_field(inst, act, target, value)``, in line (``value`` is set; with
        ``named``, ``target`` is the name of the local that holds the field's name)."""
        t = target if named else self.name("T", target)
        out += [f"{pad}fields = inst.data",
                f"{pad}if {t} in fields or {t} not in state.package_data:",
                f"{pad}    fields[{t}] = value",
                f"{pad}else:",
                f"{pad}    state.package_data[{t}] = value"]
        if act is None:
            key = self.name("D", (EK.DATA_CHANGED, self.proc.id, None))
            out.append(f"{pad}if state.wants_all or {key} in state.wanted:")
            who = "None"
        else:
            a = f"A{act.index}"
            self.names[a] = act
            out += [f"{pad}cached = {a}.flag_cache",
                    f"{pad}if (cached.bits if cached.key is state.flag_key "
                    f"else state.act_bits({a})) & 8:"]
            who = self.name("I", act.id)
        out += [f"{pad}    state.emit(CHANGED, {self.name('P', self.proc.id)}, iid, {who}, "
                f"{self.name('L', self.proc.lane)}, None, {{{t}: value}})",
                f"{pad}if state.rules:",
                f"{pad}    flow.triggers.check_rules()"]
