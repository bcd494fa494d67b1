"""Plans: the frameless first token of each workflow as straight-line Python, made at load time.

:func:`opspec.engine.lone.run` carries the one token of a new instance through its ``lone``
activities (instantaneous, one way out, no join ahead) by interpreting the graph: per
activity it asks whether it is lone, whether it runs on a pooled worker or a bound
application, whether it has assignments, a subflow to start, one successor or an XOR split,
and looks the successor up. All of that is known when the package is compiled. A *plan* is
that walk written out once per workflow as the source of one Python function (``exec`` once
per package, :func:`attach`), with only what each activity does left in it: its trace events,
its assignments, its conditions called in order, its successor's code following its own.
It does exactly what ``lone.run`` does, step for step — the same zero-time step count, the
same trace events in the same order, the same faults, the same hand-over to
:meth:`Activities.start <opspec.engine.activities.Activities.start>` (a frame made with the
token in it) at the first activity that is not lone (``tests/engine/test_plans.py`` holds
every bundled spec and the corner cases to it).

Only from source: interpreted, an instance of the dispenser's schedule workflow (start,
queue, plan, completion) costs 32k instructions instead of 45k through ``lone.run``;
compiled by mypyc, ``lone.run`` is native code and a plan (which ``exec`` makes, so it
always runs interpreted) would be slower, so :func:`attach` makes none when the engine runs
compiled. Branches that merge again are written out once per path
(the dispenser's schedule workflow: four slots into one merge); a path that comes back to
an activity already on it (a zero-time cycle) or grows past :data:`MAX_BLOCKS` goes on in
``lone.run`` with the steps counted so far.

*Resume plans* (:func:`build_resume`) are the same code for a token that has a frame: per
activity whose completion goes on into activities a plan can write out (:func:`resumable`),
what ``Activities._complete`` and then ``Activities.start`` do, called by
``Activities.body_done`` (``tests/engine/test_resume_plans.py`` holds them to the
interpreter). In the frame they also write out instantaneous activities that throw or raise
a trigger; at an activity that waits, a plan makes its activity instance and offers a plain
manual activity itself (``start_slow`` and ``Offers.offer`` in line).
"""

from __future__ import annotations

import re
import types
from collections.abc import Callable
from types import MappingProxyType
from typing import Any, Final

from opspec.engine import lone, process_deadlines
from opspec.engine.compiled import (
    K_ASYNC,
    K_CATCH,
    K_GATEWAY,
    K_MANUAL,
    K_SUBFLOW,
    K_TASK,
    K_THROW,
    S_XOR,
    CompiledActivity,
    CompiledPackage,
    CompiledProcess,
    CTransition,
    CTrigger,
)
from opspec.engine.conditions import constant_value
from opspec.engine.instances import ActivityInstance, Frame, ProcessInstance
from opspec.engine.lifecycle import COMPLETED, LIFECYCLE, RUNNING, SUSPENDED
from opspec.engine.performers import WorkItem
from opspec.engine.scope import Scope
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError
from opspec.model import ParameterMode

__all__ = ["MAX_BLOCKS", "attach", "build", "build_performed", "build_resume", "performs",
           "resumes"]

#: Activity blocks written out per plan at most (merging branches are written once per
#: path); past it, or deeper than :data:`_MAX_DEPTH` nested splits, the plan ends in
#: ``lone.run``.
MAX_BLOCKS: Final = 64
_MAX_DEPTH: Final = 24

#: whether the engine runs compiled (mypyc): its functions are then not Python functions
COMPILED: Final = not isinstance(lone.run, types.FunctionType)

#: a completed instance's state (``Flow.instance_done``'s)
ENDED: Final = LIFECYCLE.table[(RUNNING, "complete")]

_NO_TRANSITION: Final = ("no outgoing transition can be taken (no condition holds and "
                         "there is no OTHERWISE transition)")


def attach(compiled: CompiledPackage) -> None:
    """Give each workflow of ``compiled`` that starts with one token its plan
    (``CompiledProcess.plan``) and its resume plans (the plan's ``resumes``), once per
    package; none when the engine runs compiled."""
    if COMPILED or compiled.plans:
        return
    for proc in compiled.processes.values():
        if proc.one_start >= 0:
            plan: Any = build(proc, proc.one_start)
            plan.resumes = {proc.graph.activities[index]: build_resume(proc, index)
                            for index in resumable(proc)}
            plan.performs = {trans: build_performed(proc, trans.target)
                             for trans in performable(proc)}
            proc.plan = plan
    compiled.plans = True


def resumes(compiled: CompiledPackage) -> dict[CompiledActivity, Callable[[Any, Any], None]]:
    """The resume plans of ``compiled``'s workflows by the activity whose completion they
    carry on from (``Activities.body_done`` calls ``resume(activities, ai)``); empty when
    the engine runs compiled."""
    attach(compiled)
    found: dict[CompiledActivity, Callable[[Any, Any], None]] = {}
    for proc in compiled.processes.values():
        found.update(getattr(proc.plan, "resumes", None) or {})
    return found


def performs(compiled: CompiledPackage) -> dict[CTransition, Callable[[Any, Any, Any], None]]:
    """The performed-branch plans of ``compiled``'s workflows by the deferred choice's
    transition into the branch (``Flow.take`` queues ``plan(frame, activities, trans)`` in
    ``Flow.performed``'s place); empty when the engine runs compiled."""
    attach(compiled)
    found: dict[CTransition, Callable[[Any, Any, Any], None]] = {}
    for proc in compiled.processes.values():
        found.update(getattr(proc.plan, "performs", None) or {})
    return found


def performable(proc: CompiledProcess) -> list[CTransition]:
    """The branches of ``proc``'s deferred choices (not labelled ones: those run their
    branch) whose chosen activity a plan completes and carries on from
    (``Flow.performed``, ``Flow.finish``): it completes without error, escalation,
    terminate, loop or multi-instance, is no asynchronous call, and its way out is known
    before the run (as a resume plan's) or it ends the path."""
    acts = proc.graph.activities
    found = []
    for act in acts:
        if act.labelled or not (act.choice or act.kind == K_GATEWAY):
            continue
        for trans in act.choice or act.out:
            target = acts[trans.target]
            if (target.error is None and target.escalation is None and not target.terminate
                    and target.loop is None and target.mi is None and target.kind != K_ASYNC
                    and (_ways_out(target, acts) or target.next < 0 and not (
                        target.out or target.otherwise or target.choice or target.drawn))):
                found.append(trans)
    return found


def resumable(proc: CompiledProcess) -> list[int]:
    """The activities of ``proc``'s graph whose completion a resume plan carries on from:
    those that complete without end assignments, throws or ends of their own
    (``simple_end``), whose way out is known before the run (one transition into an
    activity without a join, or an exclusive split into such activities, one token each)
    and leads into at least one ``lone`` activity. Anything else completes through the
    interpreter (``Activities._complete``)."""
    acts = proc.graph.activities
    found = []
    for act in acts:
        if (not act.simple_end or act.mi is not None
                or act.fast and not act.general and act.kind != K_TASK):
            continue                        # (an activity that never waits never completes)
        targets = _ways_out(act, acts)
        if targets and any(acts[t].lone or _thrown_on(acts[t], acts) or _offered(acts[t])
                           or _chooses(acts[t]) or _caught(acts[t]) for t in targets):
            found.append(act.index)
    return found


def _offered(act: CompiledActivity) -> bool:
    """Whether a plan offers ``act`` itself (``_Writer.offer``): a plain manual activity
    without parameters, start assignments or a worker to wait for."""
    return (act.plain and act.kind == K_MANUAL and not act.params and not act.start_assign
            and not act.general)


def _caught(act: CompiledActivity) -> bool:
    """Whether a plan starts ``act`` itself (``_Writer.catch``): a catch event whose only
    waits beside its trigger are deadlines and boundary events (no start trigger or
    assignments, loop, multi-instance, duration or worker)."""
    return (act.kind == K_CATCH and act.trigger is not None and not act.plain
            and act.start_trigger is None and not act.start_assign and act.loop is None
            and act.mi is None and act.cpu == 0.0 and act.cpu_sampler is None
            and act.sampler is None and not act.general)


def _chooses(act: CompiledActivity) -> bool:
    """Whether a plan offers ``act``'s deferred choice itself (``_Writer.choice``): an
    event-based gateway whose branches are not labelled, without start assignments or a
    worker to wait for."""
    return (act.kind == K_GATEWAY and act.plain and not act.labelled and not act.general
            and not act.start_assign)


def _thrown_on(act: CompiledActivity, acts: tuple[CompiledActivity, ...]) -> bool:
    """Whether ``act``, not ``lone`` for a throw or a raised trigger only, is written out
    in a resume plan: in the instance's frame, ``Activities.start`` carries the token
    through it as through a lone one, with ``Flow.done_next``'s broadcasts (an error,
    escalation or terminate, a join or several tokens ahead: the interpreter takes it)."""
    if not act.fast or act.terminate or act.error is not None or act.escalation is not None:
        return False
    if act.next < 0 and not (act.out or act.otherwise or act.choice or act.drawn):
        return True                         # an end
    return bool(_ways_out(act, acts))


def _ways_out(act: CompiledActivity, acts: tuple[CompiledActivity, ...]) -> list[int]:
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


def build(proc: CompiledProcess, start: int) -> Callable[[Any, Any, Any], None]:
    """The plan of ``proc``'s one token from activity ``start``: ``plan(inst, activities,
    None)``, queued by ``Flow.start_process``, does what ``Flow.start_lone_at`` and
    ``lone.run(activities, inst, acts[start])`` do."""
    writer = _Writer(proc, framed=False)
    lines = ["def plan(inst, activities, _unused):",
             "    if inst.state != RUNNING:         # (Flow.start_lone_at's test)",
             "        if inst.state == SUSPENDED:",
             "            inst.defer((plan, inst, activities, None))",
             "        return",
             "    state = activities.state",
             "    if state.flag_key is not KEY:    # (the listeners' bits: see _by_selection)",
             "        SELECT(state)",
             "    flow = activities.flow",
             "    limit = state.start_limit",
             "    iid = inst.id",
             "    steps = 0"]
    if any(act.general for act in proc.graph.activities):
        lines.append("    pooled = state.pooled")
    if any(act.kind == K_TASK for act in proc.graph.activities):
        lines.append("    apps = state.apps")
    writer.block(start, (), 1, lines)
    plan: Callable[[Any, Any, Any], None] = _made(writer, lines, f"<plan of {proc.id}>",
                                                  "plan")
    return plan


def build_resume(proc: CompiledProcess, index: int) -> Callable[[Any, Any], None]:
    """The resume plan of ``proc``'s activity ``index`` (one of :func:`resumable`):
    ``resume(activities, ai)``, called by ``Activities.body_done``, does what
    ``Activities._complete`` does with ``ai`` (it leaves, its completion is traced, its
    split taken) and what ``Activities.start`` then does with the token, in the instance's
    frame."""
    writer = _Writer(proc, framed=True)
    act = proc.graph.activities[index]
    a = f"A{index}"
    writer.names[a] = act
    lines = ["def resume(activities, ai):",
             "    ai.state = DONE                  # (Activities._complete's first steps)",
             "    ai.gen += 1",
             "    frame = ai.frame",
             "    running = frame.running",
             "    key = ai.key",
             "    if key in running:",
             "        del running[key]",
             "    if ai.cleanup:",
             "        ai.undo_waits()",
             "    state = activities.state",
             "    if state.flag_key is not KEY:    # (the listeners' bits: see _by_selection)",
             "        SELECT(state)",
             "    flow = activities.flow",
             "    inst = frame.inst",
             "    limit = state.start_limit",
             "    iid = inst.id",
             "    steps = 0"]
    if any(other.general for other in proc.graph.activities):
        lines.append("    pooled = state.pooled")
    if any(other.kind == K_TASK for other in proc.graph.activities):
        lines.append("    apps = state.apps")
    lines += [f"    cached = {a}.flag_cache",
              (f"    if (cached.bits if cached.key is state.flag_key else state.act_bits({a}))"
               " & 2:"),
              f"        state.emit(COMPLETED, {writer.fields(act)})"]
    if act.next >= 0:
        writer.block(act.next, (), 1, lines)
    else:
        writer.split(index, (), 1, lines)
    resume: Callable[[Any, Any], None] = _made(
        writer, lines, f"<resume plan of {proc.id}/{index}>", "resume")
    return resume


def build_performed(proc: CompiledProcess, index: int) -> Callable[[Any, Any, Any], None]:
    """The plan of a deferred choice's branch into ``proc``'s activity ``index`` (one of
    :func:`performable`): ``performed(frame, activities, trans)``, queued by ``Flow.take``,
    does what ``Flow.performed`` does (the chosen activity starts and completes at once)
    and then what ``Activities.start`` does with the token, in the instance's frame."""
    writer = _Writer(proc, framed=True)
    act = proc.graph.activities[index]
    writer.names["PERFORMED"] = index
    lines = ["def performed(frame, activities, trans):",
             "    inst = frame.inst",
             "    flow = activities.flow",
             "    if inst.state != RUNNING or (frame.owner is not None",
             "                                 and frame.owner.state != RUNNING):",
             "        flow._dropped(frame, flow.performed, PERFORMED, trans)",
             "        return",
             "    state = activities.state",
             "    if state.flag_key is not KEY:    # (the listeners' bits: see _by_selection)",
             "        SELECT(state)",
             "    limit = state.start_limit",
             "    iid = inst.id",
             "    steps = 0"]
    if any(other.general for other in proc.graph.activities):
        lines.append("    pooled = state.pooled")
    if any(other.kind == K_TASK for other in proc.graph.activities):
        lines.append("    apps = state.apps")
    writer.block(index, (), 1, lines, performed=True)
    made: Callable[[Any, Any, Any], None] = _made(
        writer, lines, f"<performed plan of {proc.id}/{act.index}>", "performed")
    return made


_CACHED: Final = re.compile(r"\n *cached = \w+\.flag_cache(?=\n)")
_BITS: Final = re.compile(
    r"cached\.bits if cached\.key is state\.flag_key else state\.(act|proc)_bits\((\w+)\)")


def _by_selection(source: str, space: dict[str, Any]) -> str:
    """``source`` with each activity's and workflow's listener bits read from a global of
    the plan (``BITS_A3``) instead of from its cache (``RunState.act_bits``'s cached case:
    the cache, its key and the run's key read at every event a plan might trace).

    The plan tests once, where it starts, that its globals hold the bits of this run's
    listener selection (``KEY``, the run's ``flag_key``) and has ``SELECT`` set them for it
    if not (another run of the package, a new selection). A selection changes within a run
    only when a mode loads workflows (``Triggers.change_mode``), which adds selectors of the
    loaded workflows alone: the bits of the activities a plan writes out stay what they were
    (and the plan's next start sees the new key and selects again)."""
    source = _CACHED.sub("", source)
    wanted: dict[str, tuple[Any, bool]] = {}

    def named(found: re.Match[str]) -> str:
        kind, obj = found.group(1), found.group(2)
        global_name = f"BITS_{obj}"
        wanted[global_name] = (space[obj], kind == "proc")
        return global_name

    source = _BITS.sub(named, source)
    entries = tuple((global_name, obj, is_proc)
                    for global_name, (obj, is_proc) in wanted.items())

    def select(state: Any) -> None:
        for global_name, obj, is_proc in entries:
            space[global_name] = state.proc_bits(obj) if is_proc else state.act_bits(obj)
        space["KEY"] = state.flag_key

    space["KEY"] = None                     # (no run's key: the first start selects)
    space["SELECT"] = select
    return source


def _made(writer: _Writer, lines: list[str], where: str, name: str) -> Any:
    """The function ``name`` that ``lines`` define, made once."""
    space = writer.names
    source = _by_selection("\n".join(lines) + "\n", space)
    # Safe to exec: the source is the engine's own. Nothing the spec wrote (ids, names,
    # values, conditions) is in it; each is an object bound by name in ``space``
    # (``_Writer.name``), and conditions and assignments are the safe evaluator's compiled
    # functions, called (tests/engine/test_plans.py: no text of the spec reaches a plan).
    exec(compile(source, where, "exec"), space)  # noqa: S102 - see above
    made = space[name]
    made.__doc__ = source                   # what it runs, for whoever debugs it
    return made


class _Writer:
    """Writes one plan's source: a block per activity, the successor's after it."""

    def __init__(self, proc: CompiledProcess, framed: bool) -> None:
        self.proc = proc
        # in the instance's frame (a resume plan: ``Activities.start``'s steps) or before
        # it has one (the first token: ``lone.run``'s)
        self.framed = framed
        self.acts = proc.graph.activities
        self.blocks = 0
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
            "PROCESS_STARTED": EK.PROCESS_STARTED}

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
        if not performed:
            if index in path or self.blocks > MAX_BLOCKS or depth > _MAX_DEPTH:
                out.append(f"{pad}activities.start(frame, {a}, steps, limit)" if self.framed
                           else f"{pad}REST(activities, inst, {a}, steps, limit)")
                out.append(f"{pad}return")
                return
            if not (act.lone or self.framed and _thrown_on(act, self.acts)):
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
            out += [f"{pad}steps += 1",
                    f"{pad}if steps > limit:",
                    f"{pad}    state.zero_time({'frame' if self.framed else 'inst'}, {a})"]
        fields = self.fields(act)
        out += [f"{pad}cached = {a}.flag_cache",
                f"{pad}bits = cached.bits if cached.key is state.flag_key "
                f"else state.act_bits({a})",
                f"{pad}if bits & 1:",
                f"{pad}    state.emit(STARTED, {fields})"]
        if act.simple_end and not act.start_assign and act.kind != K_ASYNC:
            out += [f"{pad}if bits & 2:", f"{pad}    state.emit(COMPLETED, {fields})"]
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
                f"{pad}        activities.body_done(parent, out or None)"]

    def hand_over(self, index: int, pad: str) -> list[str]:
        """The hand-over at activity ``index`` (as in ``lone.run``): the instance gets its
        frame with the token in it (a resume plan's has one), and the token goes the
        general way from there (whether the activity is instantaneous is known here: the
        call ``start`` or ``start_slow``)."""
        a = f"A{index}"
        act = self.acts[index]
        if act.fast:
            start = [f"{pad}activities.start(frame, {a}, steps, limit)", f"{pad}return"]
        elif _offered(act):
            start = self.offer(act, pad)
        elif _caught(act):
            start = [*self.instance(act, pad), *self.catch(act, pad)]
        elif not act.plain and act.start_trigger is None:
            start = [*self.instance(act, pad), f"{pad}activities.activate(ai)", f"{pad}return"]
        elif _chooses(act):
            start = [*self.instance(act, pad), *self.started(act, pad), *self.choice(act, pad)]
        elif act.plain and not act.general and not act.start_assign:
            start = [*self.instance(act, pad), *self.started(act, pad),
                     *(self.call(act, pad) if act.kind == K_SUBFLOW
                       else [f"{pad}activities._body(ai)"]), f"{pad}return"]
        else:
            start = [f"{pad}activities.start_slow(frame, {a})", f"{pad}return"]
        if self.framed:
            return start
        return [f"{pad}frame = FRAME(GRAPH, inst, None)", f"{pad}inst.frames.append(frame)",
                f"{pad}frame.live = 1", *start]

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
            out += [f"{pad}try:",
                    f"{pad}    delay = float({self.name('V', seconds)}(inst.scope, now))",
                    f"{pad}except OpspecError as error:",
                    (f"{pad}    flow.abort(inst, {a}, "
                     f"f\"deadline cannot be computed: {{error.message}}\")"),
                    f"{pad}    return",
                    (f"{pad}state.later(delay, triggers.deadline, ai, "
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
                 f"{triggers}.caught, None)"),
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
                (f"{pad}item = ITEM(key, {self.name('P', act.process)}, iid, "
                 f"{self.name('I', act.id)}, {self.name('B', act.label)}, "
                 f"{self.name('W', act.participant)}, {self.name('L', act.lane)}, state.now, "
                 f"{self.name('APP', act.application)}, view, {ch}, "
                 f"inst.root, None)"),
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
        from opspec.engine.activities import MAX_CALL_DEPTH  # (activities imports plans)
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
            made = [f"{p}priority = called.priority",
                    f"{p}if inst.priority > priority:",
                    f"{p}    priority = inst.priority",
                    (f"{p}child = INSTANCE(new_id, called, child_data, child_scope, priority, "
                     f"ai, inst.root, state.now, RUNNING, None)"),
                    f"{p}child.depth = inst.depth + 1",
                    f"{p}child.partner = inst.partner"]
            started = "{\"trigger\": None, \"parent\": iid}"
        else:
            made = [(f"{p}child = INSTANCE(new_id, called, child_data, child_scope, "
                     f"called.priority, None, new_id, state.now, RUNNING, {trigger})")]
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
                *made,
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
                f"{pad}ai = ACTIVITY(key, A{act.index}, frame, state.now, RUNNING)",
                f"{pad}frame.running[key] = ai"]

    def started(self, act: CompiledActivity, pad: str) -> list[str]:
        """A plain activity's start traced (``Activities.start_slow``); ``cached`` is left
        set for its offer."""
        a = f"A{act.index}"
        return [f"{pad}cached = {a}.flag_cache",
                (f"{pad}bits = cached.bits if cached.key is state.flag_key "
                 f"else state.act_bits({a})"),
                f"{pad}if bits & 1:",
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
                (f"{pad}item = ITEM(key, {self.name('P', act.process)}, iid, "
                 f"{self.name('I', act.id)}, {self.name('B', act.label)}, "
                 f"{self.name('W', act.participant)}, {self.name('L', act.lane)}, state.now, "
                 f"{self.name('APP', act.application)}, view, (), inst.root, None)"),
                f"{pad}ai.item = item",
                f"{pad}ai.performer = performer",
                f"{pad}ai.waiting = \"performer\"",
                f"{pad}state.offered[key] = ai",
                (f"{pad}if (cached.bits if cached.key is state.flag_key "
                 f"else state.act_bits({a})) & 4:"),
                f"{pad}    state.emit(OFFERED, {fields}, None)",
                f"{pad}performer.offer(item)",
                f"{pad}return"]

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
                chain += [f"{inner}flow.abort(inst, {a}, {_NO_TRANSITION!r})", f"{inner}k = -1"]
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
                  out: list[str]) -> None:
        """``Flow.set_field(inst, act, target, value)``, in line (``value`` is set)."""
        t = self.name("T", target)
        out += [f"{pad}data = inst.data",
                f"{pad}if {t} in data or {t} not in state.package_data:",
                f"{pad}    data[{t}] = value",
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
