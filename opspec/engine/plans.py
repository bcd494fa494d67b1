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
manual activity itself (``start_slow`` and ``Offers.offer`` in line). For an activity that
does not loop, the resume plan is a *done plan*: ``Activities.body_done``'s own steps first,
queued by ``Offers.performer_complete`` in ``body_done``'s place (a Python frame less an
answer). The activity instances, frames, process instances and work items a plan makes are
made without calling their classes (``object.__new__`` and their fields stored in line, from
the tables in :mod:`opspec.engine.instances` and the work item's ``FIELDS``): from source a
class call costs about 150 ns more an object.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any, Final

from opspec.engine import lone
from opspec.engine.compiled import (
    K_ASYNC,
    K_GATEWAY,
    K_TASK,
    CompiledActivity,
    CompiledPackage,
    CompiledProcess,
    CTransition,
)
from opspec.engine.plan_waits import catches_itself, chooses_itself, offers_itself
from opspec.engine.plan_writer import MAX_BLOCKS, Writer, by_selection, thrown_on, ways_out

__all__ = ["MAX_BLOCKS", "attach", "build", "build_performed", "build_resume", "dones",
           "performs", "resumes"]

#: whether the engine runs compiled (mypyc): its functions are then not Python functions
COMPILED: Final = not isinstance(lone.run, types.FunctionType)


def attach(compiled: CompiledPackage) -> None:
    """Give each workflow of ``compiled`` that starts with one token its plan
    (``CompiledProcess.plan``) and its resume plans (the plan's ``resumes``, and ``dones``
    for the activities that do not loop), once per package; none when the engine runs
    compiled."""
    if COMPILED or compiled.plans:
        return
    for proc in compiled.processes.values():
        if proc.one_start >= 0:
            plan: Any = build(proc, proc.one_start)
            acts = proc.graph.activities
            plan.resumes = {acts[index]: build_resume(proc, index)
                            for index in resumable(proc) if acts[index].loop is not None}
            plan.dones = {acts[index]: build_resume(proc, index, queued=True)
                          for index in resumable(proc) if acts[index].loop is None}
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


def dones(compiled: CompiledPackage) -> dict[CompiledActivity, Callable[[Any, Any, Any], None]]:
    """The done plans of ``compiled``'s workflows (resume plans with ``Activities.body_done``'s
    steps before them, for activities that do not loop) by the activity whose answer they
    take: ``done(ai, activities, data)``, queued by ``Offers.performer_complete`` in
    ``body_done``'s place and called by ``body_done``; empty when the engine runs
    compiled."""
    attach(compiled)
    found: dict[CompiledActivity, Callable[[Any, Any, Any], None]] = {}
    for proc in compiled.processes.values():
        found.update(getattr(proc.plan, "dones", None) or {})
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
                    and (ways_out(target, acts) or target.next < 0 and not (
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
        targets = ways_out(act, acts)
        if targets and any(acts[t].lone or thrown_on(acts[t], acts) or offers_itself(acts[t])
                           or chooses_itself(acts[t]) or catches_itself(acts[t]) for t in targets):
            found.append(act.index)
    return found


def build(proc: CompiledProcess, start: int) -> Callable[[Any, Any, Any], None]:
    """The plan of ``proc``'s one token from activity ``start``: ``plan(inst, activities,
    None)``, queued by ``Flow.start_process``, does what ``Flow.start_lone_at`` and
    ``lone.run(activities, inst, acts[start])`` do."""
    writer = Writer(proc, framed=False)
    lines = ["def plan(inst, activities, _unused):",
             "    if inst.state != RUNNING:         # (Flow.start_lone_at's test)",
             "        if inst.state == SUSPENDED:",
             "            inst.defer((plan, inst, activities, None))",
             "        return",
             "    flow = activities.flow",
             *_token_locals(proc)]
    writer.block(start, (), 1, lines)
    plan: Callable[[Any, Any, Any], None] = _made(writer, lines, f"<plan of {proc.id}>",
                                                  "plan")
    return plan


def build_resume(proc: CompiledProcess, index: int, queued: bool = False) -> Any:
    """The resume plan of ``proc``'s activity ``index`` (one of :func:`resumable`):
    ``resume(activities, ai)``, called by ``Activities.body_done``, does what
    ``Activities._complete`` does with ``ai`` (it leaves, its completion is traced, its
    split taken) and what ``Activities.start`` then does with the token, in the instance's
    frame. ``queued`` (an activity without a loop): ``done(ai, activities, data)``, the
    same with ``body_done``'s steps before it (a ready-queue item in ``body_done``'s place:
    a Python frame less an answer)."""
    writer = Writer(proc, framed=True)
    act = proc.graph.activities[index]
    a = f"A{index}"
    writer.names[a] = act
    # (a done plan reads the frame, the instance and the run's parts once, before its data)
    parts = ["    frame = ai.frame", "    inst = frame.inst", "    state = activities.state",
             "    flow = activities.flow", "    iid = inst.id"]
    first = (["def done(ai, activities, data):",
              "    if ai.state != RUNNING:          # (Activities.body_done's steps)",
              "        return",
              *parts[:2],
              "    if inst.state == SUSPENDED:",
              "        inst.defer((activities.body_done, ai, data, None))",
              "        return",
              *parts[2:],
              "    if data:                         # (Flow.set_field, each in line)",
              "        if state.flag_key is not KEY:",
              "            SELECT(state)",
              "        for key, value in data.items():"]
             if queued else ["def resume(activities, ai):"])
    if queued:
        writer.set_field(act, "key", "            ", first, named=True)
    lines = [*first,
             "    ai.state = DONE                  # (Activities._complete's first steps)",
             "    ai.gen += 1",
             *([] if queued else parts[:1]),
             "    running = frame.running",
             "    key = ai.key",
             "    if key in running:",
             "        del running[key]",
             "    if ai.cleanup:",
             "        ai.undo_waits()",
             *([] if queued else parts[1:]),
             "    if state.flag_key is not KEY:    # (the listeners' bits: see by_selection)",
             "        SELECT(state)",
             "    limit = state.start_limit"]
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
    return _made(writer, lines, f"<{'done' if queued else 'resume'} plan of {proc.id}/{index}>",
                 "done" if queued else "resume")


def build_performed(proc: CompiledProcess, index: int) -> Callable[[Any, Any, Any], None]:
    """The plan of a deferred choice's branch into ``proc``'s activity ``index`` (one of
    :func:`performable`): ``performed(frame, activities, trans)``, queued by ``Flow.take``,
    does what ``Flow.performed`` does (the chosen activity starts and completes at once)
    and then what ``Activities.start`` does with the token, in the instance's frame."""
    writer = Writer(proc, framed=True)
    act = proc.graph.activities[index]
    writer.names["PERFORMED"] = index
    lines = ["def performed(frame, activities, trans):",
             "    inst = frame.inst",
             "    flow = activities.flow",
             "    if inst.state != RUNNING or (frame.owner is not None",
             "                                 and frame.owner.state != RUNNING):",
             "        flow._dropped(frame, flow.performed, PERFORMED, trans)",
             "        return",
             *_token_locals(proc)]
    writer.block(index, (), 1, lines, performed=True)
    made: Callable[[Any, Any, Any], None] = _made(
        writer, lines, f"<performed plan of {proc.id}/{act.index}>", "performed")
    return made


def _token_locals(proc: CompiledProcess) -> list[str]:
    """The locals a plan that carries a token reads (``inst`` and ``activities`` given):
    the run state with this run's listener bits selected, the zero-time guard's limit and
    count, and the pooled processor and the applications where ``proc`` has any."""
    lines = ["    state = activities.state",
             "    if state.flag_key is not KEY:    # (the listeners' bits: see by_selection)",
             "        SELECT(state)",
             "    limit = state.start_limit",
             "    iid = inst.id"]
    if any(act.general for act in proc.graph.activities):
        lines.append("    pooled = state.pooled")
    if any(act.kind == K_TASK for act in proc.graph.activities):
        lines.append("    apps = state.apps")
    return lines


def _made(writer: Writer, lines: list[str], where: str, name: str) -> Any:
    """The function ``name`` that ``lines`` define, made once."""
    space = writer.names
    source = by_selection("\n".join(lines) + "\n", space)
    # Safe to exec: the source is the engine's own. Nothing the spec wrote (ids, names,
    # values, conditions) is in it; each is an object bound by name in ``space``
    # (``Writer.name``), and conditions and assignments are the safe evaluator's compiled
    # functions, called (tests/engine/test_plans.py: no text of the spec reaches a plan).
    exec(compile(source, where, "exec"), space)  # noqa: S102 - see above
    made = space[name]
    made.__doc__ = source                   # what it runs, for whoever debugs it
    return made
