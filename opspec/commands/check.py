"""Check the soundness of each process (deadlocks, livelocks, dead activities, improper
completion, graph conformance).

Explore each process's control flow with data abstracted (every conditional branch may be
taken) and report deadlocks, livelocks, activities that can never run, improper completion,
AND-joins that can't fire and unbounded places, each with a witness path; plus violations of
the package's declared graph conformance class (docs/soundness.md, opspec.model.soundness).

SPEC is an XPDL or BPMN file, a compiled workflow script (.wfs: checked as the spec it was
compiled from), or a folder of specs.

Each problem prints as 'path:line: error: process: message' with its witness (the activities
fired from the start) on the next line, then one line per process level and a summary per
file; --json prints one JSON object per file instead (JSON Lines).

A spec with errors (any that opspec validate reports: the reader's, the structural checks'
such as a dangling transition, what the engine refuses to compile) is still explored when a
package could be built (its conditions do not matter here), but it is never called sound: the
errors are printed first and make the status 1, and a process level with an error in its own
lines is 'not sound' whatever the exploration of what could be read of it found.

Exit status: 0 every process level is sound; 1 a problem was found, a spec has errors, or the
check ran out of its budget (more than --max-states states in a level, or out of memory): that
verdict is inconclusive, never "sound"; 2 usage or I/O problems (a missing path, an unreadable
file, an unknown --process). Over several files, the highest status wins. Memory is bounded
by --max-states (docs/soundness.md gives the bound).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.commands._args import add_json, command

if TYPE_CHECKING:
    from collections.abc import Sequence

    from opspec.errors import Diagnostic
    from opspec.model.soundness import SoundnessReport

__all__ = ["register", "run"]


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be at least 1")
    return value


def register(subparsers: Any) -> None:
    parser = command(subparsers, "check", __doc__)
    parser.add_argument("specs", nargs="+", metavar="SPEC", help="spec files or folders")
    add_json(parser, "one JSON object per file (JSON Lines)")
    parser.add_argument("--max-states", type=_positive, default=100_000, metavar="N",
                        help="markings explored per process level before giving up "
                        "(default 100000)")
    parser.add_argument("--process", metavar="ID", help="check only the process with this Id")
    parser.add_argument("--schedulability", action="store_true",
                        help="also print the fixed-priority response-time analysis of the "
                        "periodic workflows beside the preemptive engine's simulation of "
                        "one hyperperiod (one processor)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from opspec.commands._check_levels import errors_by_level
    from opspec.commands._spec import where_to_look
    from opspec.errors import Severity
    from opspec.model.instance_starts import called_processes
    from opspec.model.soundness import SoundnessReport, check_process
    from opspec.xpdl.gate import RUNS_DIFFERENTLY
    from opspec.xpdl.loader import load_package
    from opspec.xpdl.validate import IO_CODES, spec_files

    files, usage = spec_files(args.specs, where_to_look=where_to_look)
    for message in usage:
        print(f"opspec check: {message}", file=sys.stderr)
    worst = 2 if usage else 0
    for path in files:
        if Path(path).suffix == ".wfs":
            # a compiled script holds the package as the engine runs it: checked as its spec
            from opspec.commands.show import load_script

            result = load_script(str(path))
        else:
            result = load_package(path)
        errors = result.errors
        if result.package is None:
            _print_unloadable(path, result.diagnostics, as_json=args.json)
            io = any(d.code in IO_CODES for d in result.diagnostics)
            worst = max(worst, 2 if io else 1)
            continue
        for warning in result.diagnostics:
            # soundness is of what opspec runs: say where that differs from the standard
            if warning.code == RUNS_DIFFERENTLY and warning.severity is Severity.WARNING:
                print(f"opspec check: {warning}", file=sys.stderr)
        # conditions are abstracted, so a spec whose errors leave its control flow readable
        # (a condition opspec cannot parse, a duplicate lane id) is still checked
        package = result.package
        errors = tuple(_spec_errors(package, errors, result.packages))
        from opspec.commands._spec import nesting_problem

        if nesting_problem(package) is not None:
            # blocks nested past what the compiler and the exploration follow (listed
            # among the errors): nothing can be checked
            _print_unloadable(path, errors, as_json=args.json, nested=True)
            worst = max(worst, 1)
            continue
        processes = [p for p in package.processes
                     if args.process is None or p.id == args.process]
        if args.process is not None and not processes:
            names = ", ".join(p.id for p in package.processes) or "none"
            print(f"opspec check: {path}: no process {args.process!r} (its processes: "
                  f"{names})", file=sys.stderr)
            worst = 2
            continue
        reports: list[SoundnessReport] = []
        called = called_processes(package)
        try:
            for process in processes:
                reports.extend(check_process(process, conformance=package.conformance_class,
                                             max_states=args.max_states,
                                             called=process.id in called))
            reports = _with_zero_time_cycles(package, reports, [p.id for p in processes])
        except MemoryError:
            # each level's exploration reports its own; this is what is left (the net of a
            # huge level, the graph conformance or zero-time analyses): inconclusive too
            done = {r.process for r in reports}
            reports = [*reports, *(SoundnessReport(p.id, 0, False, (), stopped="memory")
                                   for p in processes if p.id not in done)]
        # a script's lines are those of the spec it was compiled from
        lines_in = (package.source or None) if Path(path).suffix == ".wfs" else None
        status = _print(path, reports, errors, as_json=args.json, max_states=args.max_states,
                        in_levels=errors_by_level(package, errors), lines_in=lines_in)
        if getattr(args, "schedulability", False) and not errors:
            status = max(status, _schedulability(package, as_json=args.json))
        worst = max(worst, status)
    return worst


def _schedulability(package: Any, *, as_json: bool) -> int:
    """Response-time analysis beside a simulation of one hyperperiod from a synchronous
    release on one preemptive processor; 1 when a workflow misses its deadline."""
    from opspec.engine.config import EngineConfig
    from opspec.model.schedulability import analyse, hyperperiod, tasks_of

    tasks = analyse(tasks_of(package))
    if not tasks:
        if not as_json:
            print("  schedulability: no periodic workflow declares a CpuDemand")
        return 0
    horizon = hyperperiod(tasks)
    config = EngineConfig(processor_model="preemptive", workers=1, switch_cost=0.0,
                          priorities=max(t.priority for t in tasks) + 1)
    # the whole package runs (its other workflows take processor time too); the table
    # follows the periodic ones
    wanted = {t.workflow for t in tasks}
    started: dict[int, tuple[str, float]] = {}
    worst: dict[str, float] = {}

    def listen(event: Any) -> None:
        if event.process not in wanted:
            return
        if event.kind == "process.started":
            started[event.instance] = (event.process, event.time)
        elif event.kind == "process.completed" and event.instance in started:
            _workflow, at = started.pop(event.instance)
            worst[event.process] = max(worst.get(event.process, 0.0), event.time - at)

    listen.selects = {(k, w, None) for k in ("process.started", "process.completed")  # type: ignore[attr-defined]
                      for w in wanted}
    from opspec.request import RunRequest, prepare

    # one run as every door makes it (its world, seed 0), nobody on the user lane
    prepare(RunRequest(package, until=horizon, no_user=True, config=config,
                       listeners=(listen,))).execute()
    unfinished = set()
    for workflow, at in started.values():       # still running at the horizon: at least
        worst[workflow] = max(worst.get(workflow, 0.0), horizon - at)
        unfinished.add(workflow)
    # a workflow that never ran in the simulation (outside the initial mode) is judged by
    # the analysis alone
    # a task without a bounded demand (or behind one) has no analysis: the simulation alone
    # judges it (one stochastic hyperperiod: evidence, not proof)
    no_bound = {t.workflow for t in tasks if t.response is None and (
        t.unbounded or any(o.unbounded for o in tasks if o.priority >= t.priority))}
    misses = [t for t in tasks if (t.response is None and t.workflow not in no_bound)
              or worst.get(t.workflow, 0.0) > t.deadline + 1e-9]
    if as_json:
        print(json.dumps({"schedulability": [
            {"workflow": t.workflow, "period_s": t.period, "demand_s": t.demand,
             "priority": t.priority, "deadline_s": t.deadline, "analysis_s": t.response,
             "simulated_worst_s": worst.get(t.workflow),
             "demand_unbounded": t.workflow in no_bound,
             "unfinished_at_end": t.workflow in unfinished} for t in tasks],
            "hyperperiod_s": horizon}))
    else:
        print(f"  schedulability (one preemptive processor, fixed priorities, release at 0, "
              f"simulated over {horizon:g} s):")
        print(f"    {'workflow':<20}{'prio':>5}{'C s':>9}{'T s':>9}{'D s':>9}"
              f"{'RTA R s':>10}{'sim max s':>11}  verdict")
        for t in tasks:
            simulated = worst.get(t.workflow)
            shown = ("not run" if simulated is None else
                     f"{'>= ' if t.workflow in unfinished else ''}{simulated:.4g}")
            analysis = (f"{t.response:.4g}" if t.response is not None else
                        "no bound" if t.workflow in no_bound else "> D")
            verdict = ("MISSES its deadline" if t in misses else
                       "met in the simulation (no worst case: a demand without bound)"
                       if t.workflow in no_bound else "meets its deadline")
            print(f"    {t.workflow:<20}{t.priority:>5}{t.demand:>9.4g}{t.period:>9.4g}"
                  f"{t.deadline:>9.4g}{analysis:>10}{shown:>11}  {verdict}")
    return 1 if misses else 0


def _with_zero_time_cycles(package: Any, reports: list[SoundnessReport],
                           processes: list[str]) -> list[SoundnessReport]:
    """Add each level's zero-time cycles (warnings, see opspec.engine.zero_time_check); a
    package the engine cannot compile has its errors printed already and gets none."""
    from opspec.engine.compiled import compile_package
    from opspec.engine.zero_time_check import zero_time_cycles
    from opspec.errors import OpspecError

    try:
        found = zero_time_cycles(compile_package(package), processes)
    except OpspecError:
        return reports
    out = []
    for report in reports:
        mine = tuple(p for p in found if p.process == report.process)
        out.append(replace(report, problems=report.problems + mine) if mine else report)
    return out


def _spec_errors(package: Any, load_errors: Sequence[Diagnostic],
                 packages: Any) -> list[Diagnostic]:
    """Every error ``opspec validate`` reports, so that a spec validate refuses is never
    called sound: the reader's, the structural checks' (a dangling transition, an undefined
    participant…), a mode Source that is missing or broken, a monitor or a world that cannot
    be built and, when there is no other error, what the engine refuses to compile."""
    from opspec.commands._spec import NOT_RUNNABLE, engine_diagnostics
    from opspec.errors import Severity
    from opspec.model.checks import check_package
    from opspec.xpdl.validate import merge_diagnostics, mode_source_diagnostics

    structural = [d for d in check_package(package, packages=packages) if d.severity is Severity.ERROR]
    errors = [*load_errors, *structural, *mode_source_diagnostics(package)]
    engine = [d for d in engine_diagnostics(package, world=True)
              if d.severity is Severity.ERROR]
    if errors:          # what keeps the engine from compiling is most likely listed already
        engine = [d for d in engine if d.code != NOT_RUNNABLE]
    return list(merge_diagnostics(errors, engine))


def _errors_json(errors: Sequence[Diagnostic]) -> list[dict[str, Any]]:
    # the hint too, as validate's --json: a reader limit's message says what is wrong, only
    # its hint what to change
    return [{"line": d.location.line, "severity": d.severity.value, "code": d.code,
             "message": d.message, "hint": d.hint} for d in errors]


def _print_unloadable(path: Path, errors: Sequence[Diagnostic], *, as_json: bool,
                      nested: bool = False) -> None:
    """Print the errors of a file that is not checked and why; ``nested``: it was read, but
    its blocks nest past what the check follows."""
    if as_json:
        print(json.dumps({
            "path": str(path), "sound": False, "loaded": nested, "processes": [],
            "problems": [], "errors": _errors_json(errors)}, ensure_ascii=False))
        return
    for diagnostic in errors:
        print(diagnostic)
    from opspec.xpdl.validate import IO_CODES

    if errors and all(d.code in IO_CODES for d in errors):
        return      # a device, a pipe, no permission: the line above says it all
    if nested:
        why = ("its blocks nest deeper than the check follows; change them as the nesting "
               "error above advises")
    elif any(d.code == "resource-limit" for d in errors):
        # a well-formed file, maybe: "could not be read" would not say what to change
        why = ("the file is beyond a safety limit of the XML reader, so it was not read; "
               "change it as the error above advises")
    elif Path(path).suffix == ".wfs":
        why = ("the file could not be read as a compiled workflow script; fix or recompile "
               "it as the error above says")
    else:
        why = ("the file could not be read as a spec (XPDL or BPMN); fix the errors listed "
               "above")
    print(f"{path}: not checked: {why}")


def _problem_json(p: Any) -> dict[str, Any]:
    return {"kind": p.kind, "severity": p.severity, "process": p.process,
            "activity": p.activity, "line": p.line, "message": p.message,
            "witness": list(p.witness)}


def _print(path: Path, reports: list[SoundnessReport], errors: Sequence[Diagnostic], *,
           as_json: bool, max_states: int,
           in_levels: dict[str, list[Diagnostic]] | None = None,
           lines_in: str | None = None) -> int:
    """Print one file's verdict; return its exit status (0 or 1). Load ``errors`` make it
    1, and so does an inconclusive level (the budget ran out; the file is never called
    sound then). A level with errors in it (``in_levels``: the errors by level) is never
    called sound either, whatever the exploration of what could be read of it found.
    ``lines_in``: the file the problems' lines are in, when not ``path`` (a compiled
    script's are its spec's)."""
    in_levels = in_levels or {}
    problems = [p for r in reports for p in r.problems]
    failing = [p for p in problems if p.severity == "error"]
    undecided = [r for r in reports if not r.complete]
    if as_json:
        print(json.dumps({
            "path": str(path), **({"lines_in": lines_in} if lines_in else {}),
            "sound": not failing and not undecided and not errors,
            "loaded": True,
            "max_states": max_states,
            "inconclusive": bool(undecided),
            "processes": [{"process": r.process, "states": r.states, "complete": r.complete,
                           "sound": r.sound and r.process not in in_levels, "problems": sum(
                               1 for p in r.problems if p.severity == "error"),
                           **({"spec_errors": len(in_levels[r.process])}
                              if r.process in in_levels else {}),
                           **({"stopped": r.stopped} if r.stopped else {})}
                          for r in reports],
            "problems": [_problem_json(p) for p in failing],
            "errors": _errors_json(errors),
            # warnings (zero-time cycles) only when there are some
            **({"warnings": cautions} if (cautions := [
                _problem_json(p) for p in problems if p.severity != "error"]) else {}),
            }, ensure_ascii=False))
    else:
        for diagnostic in errors:
            print(diagnostic)
        for problem in problems:
            where = (f"{lines_in or path}:{problem.line}" if problem.line else str(path))
            print(f"{where}: {problem.severity}: {problem.process}: {problem.message}")
            if problem.witness:
                cyclic = problem.kind == "conformance" and len(problem.witness) > 1 and (
                    problem.witness[0] == problem.witness[-1])
                label = "cycle" if cyclic else "witness"
                print(f"    {label}: {' -> '.join(problem.witness)}")
        for report in reports:
            if report.stopped == "memory":
                print(f"{path}: warning: {report.process}: out of memory after "
                      f"{report.states} states: inconclusive (lower --max-states to stay "
                      "within this machine's memory, or simplify the process)")
            elif not report.complete:
                print(f"{path}: warning: {report.process}: more than {max_states} states: "
                      "inconclusive (raise --max-states, or simplify the process)")
        for report in reports:
            warned = sum(1 for p in report.problems if p.severity != "error")
            also = f", {warned} warning(s)" if warned else ""
            mine = in_levels.get(report.process)
            verdict = ("sound" + also if report.sound and not mine
                       else "no problem" + also if report.sound
                       else f"{len(report.problems) - warned} problem(s)" + also
                       if len(report.problems) > warned else "inconclusive" + also)
            if mine:
                # the exploration followed only what could be read of this level
                lines = ", ".join(str(d.location.line) for d in mine)
                verdict = (f"not sound: {len(mine)} spec error(s) in it "
                           f"(line{'s' if len(mine) > 1 else ''} {lines}); "
                           f"in what could be read of it: {verdict}")
            print(f"{path}: {report.process}: {verdict} ({report.states} states)")
        sound = sum(1 for r in reports if r.sound and r.process not in in_levels)
        warnings = len(problems) - len(failing)
        verdict = "not sound (the spec has errors): " if errors else ""
        elsewhere = len(errors) - sum(len(in_levels.get(r.process, ())) for r in reports)
        where = ("" if not elsewhere else " outside these process levels"
                 if elsewhere == len(errors) else f", {elsewhere} of them outside these "
                 "process levels")
        print(f"{path}: {verdict}{sound} of {len(reports)} process level(s) sound, "
              f"{len(failing)} problem(s)" + (f", {warnings} warning(s)" if warnings else "") + (
                  f", {len(errors)} spec error(s){where} (see `opspec validate`)"
                  if errors else ""))
    return 1 if failing or errors or undecided else 0
