"""Run one simulation of a spec and show what happened.

Run SPEC (XPDL, BPMN 2.0 or .wfs) once on the simulated clock, device workflows and the user
lane together, and print a timeline, the spec's metrics and a summary (or one JSON object with
--json).

The user lane is performed by --script FILE (exact actions), --user-model FILE|PRESET (a
stochastic user), or by default the spec's companion SPEC.users.toml when there is one.
--trace FILE streams every event to JSON Lines as the run goes (flushed on every exit path, so
an interrupted run keeps what happened). --bind PARTICIPANT=URL binds participants to serial
devices (devices/README.md); a bound real device switches the run to wall-clock time.

Exit status: 0 the run ended normally; 1 the run found a problem (a deadlock, an aborted
instance, a device fault); 2 usage, configuration or I/O errors. With nobody on the user lane
(--no-user, or no user model at all), user-lane instances still waiting for their performer at
the end are the expected end of a devices-only run: said in one line, not reported as
deadlocks, not exit 1.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.clock import clock_time, figure, span
from opspec.commands import _args
from opspec.errors import ConfigurationError, OpspecError

if TYPE_CHECKING:
    from opspec.engine.simulation import RunResult
    from opspec.engine.trace import TraceEvent
    from opspec.model import MetricDefinition

__all__ = ["json_metrics", "register", "run", "timeline_line"]

def register(subparsers: Any) -> None:
    parser = _args.command(subparsers, "run", __doc__)
    _args.add_spec(parser)
    length = parser.add_mutually_exclusive_group()
    _args.add_days(length, what=" to run")
    length.add_argument("--until", metavar="T",
                        help="simulated end time: seconds, or a duration (8h, PT8H, 10:00 "
                        "for 10 h)")
    _args.add_seed(parser, what="run seed: draws as user 0 of opspec evaluate --seed")
    user = parser.add_mutually_exclusive_group()
    user.add_argument("--script", metavar="FILE",
                      help="a scripted user (TOML/JSON steps, or a recorded walkthrough)")
    _args.add_user_model(user, role="a stochastic user: ")
    user.add_argument("--no-user", action="store_true",
                      help="nobody performs the user lane (ignore SPEC.users.toml)")
    _args.add_run_inputs(parser, per_user=False)
    parser.add_argument("--trace", metavar="FILE", help="write the full trace as JSON Lines")
    _args.add_engine_config(parser)
    parser.add_argument("--processor-model",
                        choices=("dedicated", "pooled", "preemptive", "priority-queues"),
                        help="override the configuration's processor model "
                        "(docs/processor-models.md)")
    parser.add_argument("--workers", type=int, help="override the pooled model's workers "
                        "(the processors of the preemptive and priority-queues models)")
    parser.add_argument("--queue-workers", type=int, metavar="N",
                        help="priority-queues model: worker threads per priority queue")
    parser.add_argument("--switch-cost", type=float, metavar="SECONDS",
                        help="override the pooled model's cost of one context switch")
    parser.add_argument("--realtime", action="store_true",
                        help="run against the wall clock (see --speed)")
    parser.add_argument("--speed", type=float, default=None,
                        help="with --realtime: simulated seconds per wall second (default 1)")
    _args.add_device_options(parser)
    parser.add_argument("--timeline", choices=("brief", "all", "none"), default="brief",
                        help="which events the printed timeline shows (default brief)")
    parser.add_argument("--timing", action="store_true",
                        help="report per-workflow response times, jitter, deadline misses "
                        "and the pooled model's context switches")
    _args.add_json(parser, "one JSON object (metrics shaped as opspec evaluate --json)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from opspec.branch_choices import parse_branch_options
    from opspec.commands._params import read_run_inputs
    from opspec.commands._wrong_file import misplaced
    from opspec.engine.trace_sinks import JsonlSink
    from opspec.request import RunRequest, prepare
    from opspec.run_rules import check_days, parse_until

    if args.days is not None:
        check_days(args.days, name="--days")
    try:
        prepared = prepare(RunRequest(
            args.spec, seed=args.seed, days=args.days,
            until=None if args.until is None else parse_until(args.until, name="--until"),
            script=args.script, user_model=args.user_model, no_user=args.no_user,
            branches=parse_branch_options(args.branch) or None))
    except OpspecError as error:
        # a user model given to --script, a spec to --user-model: say so
        raise misplaced(error, (("SPEC", args.spec), ("--script", args.script),
                                ("--user-model", args.user_model))) from None
    if args.script:
        from opspec.tui.replay import refuse_nothing_to_replay, script_notes

        end_given = args.days is not None or args.until is not None
        if not end_given:
            # a walkthrough quit at 0 s: the whole run without the person is not that
            # session (its summary printed no command; --replay refuses it too)
            refuse_nothing_to_replay(args.script, "--script")
        # a recording of a session quit at 12:34, or run with another seed: said, as the
        # walkthrough's --replay would have ended there and taken its seed
        for note in script_notes(args.script, horizon=prepared.horizon, seed=args.seed,
                                 end_given=end_given):
            print(f"opspec run: note: {note}", file=sys.stderr)
    for warning in prepared.warnings:
        print(f"opspec run: {warning}", file=sys.stderr)
    package, compiled = prepared.package, prepared.compiled
    horizon, user = prepared.horizon, prepared.user
    if args.trace:
        _refuse_trace_over_input(args, package)
    # a bad value stops us before the run; the lone run is run 0 of its seed (as user 0 of
    # opspec evaluate --seed): drawn values and a data file's first row
    inputs = read_run_inputs(args.param, args.params, package)
    params = inputs.for_run(args.seed, 0) or None
    config = _config(args)
    out = sys.stdout
    printer = _timeline(args, compiled, out)
    listeners: list[Any] = []
    with contextlib.ExitStack() as stack:
        devices = _devices(args, stack, compiled)  # a port that won't open stops us here
        clock_note = None
        if devices is not None:                  # wall clock for devices, at which speed
            config, clock_note = devices.clock(config, args.speed, horizon)
        if not args.json:
            print(f"opspec run: {package.name or package.id} ({args.spec}), seed {args.seed}, "
                  f"for {span(horizon)} simulated", file=out)
            print(f"  user lane: {user.describe}", file=out)
            if inputs.draws or inputs.rows:
                print(f"  run inputs: {inputs.describe()}; this run: "
                      + ", ".join(f"{k} = {v!r}" for k, v in (params or {}).items()), file=out)
            print(f"  engine: {config.processor_model}"
                  + (f", {config.workers} worker(s)" if config.processor_model == "pooled" else
                     f", {config.workers} processor(s)" if config.pooled else "")
                  + (f", {config.queue_workers} worker(s) per queue"
                     if config.processor_model == "priority-queues" else "")
                  + (f", wall clock at {config.speed:g}x" if config.realtime else ""), file=out)
        if devices is not None:
            for note in devices.notes:
                if not args.json:
                    print(f"  device: {note}", file=out)
            if clock_note:
                print(f"  {clock_note}", file=sys.stderr if args.json else out)
        sink = None
        if args.trace:
            sink = stack.enter_context(_open_sink(JsonlSink, args.trace, {
                "spec": str(args.spec), "seed": args.seed, "package": package.id}))
            listeners.append(sink)
        timing = None
        if args.timing:
            from opspec.engine.timing import TimingListener

            timing = TimingListener()
            listeners.append(timing)
        if printer is not None:
            listeners.append(printer)
            folding = getattr(printer, "periodic", ())
            if folding:
                from opspec.commands.run_timeline import FULL

                print(f"  timeline: brief; periodic workflows ({', '.join(folding)}): "
                      f"their first {FULL} instances, then a line each per simulated minute; "
                      "deadline misses and failures always (--timeline all: every event)",
                      file=out)
            print(file=out)
        if devices is not None:   # after the trace opened: Ctrl+C still traces what was open
            from opspec.commands.devices_summary import report_when_interrupted

            stack.push(report_when_interrupted(devices, sys.stderr))
        outcome = prepared.but(config=config, listeners=tuple(listeners),
                               devices=devices, params=params).build().execute()
        result = outcome.result
        if printer is not None:
            printer.finish(float(result.summary.get("time", 0.0)))
        absent = _waiting_for_absent_user(result.summary, compiled, user)
        monitors = {r.monitor: r for r in outcome.monitors}
        medians = outcome.medians
        device_report = devices.report() if devices is not None else None
    timing_summary = timing.summary() if timing is not None else None
    if args.json:
        doc = _json_document(args, package, horizon, result, device_report, medians)
        if params:
            doc["params"] = params
        if absent:
            doc["deadlocks"] = [d.get("message") for d in _real_deadlocks(result, absent)]
            doc["waiting_for_user"] = {"instances": len(absent),
                                       "note": _absent_note(absent, args.no_user)}
        if monitors:
            doc["monitors"] = {text: {"violations": r.count, "first": [
                {"time": v.time, "message": v.message, "events": [e.seq for e in v.events]}
                for v in r.violations[:MONITOR_SHOWN]]}
                for text, r in monitors.items()}
        if timing_summary is not None:
            doc["timing"] = timing_summary
        print(json.dumps(doc, default=str, allow_nan=False))
    else:
        if timing_summary is not None:
            _print_timing(out, timing_summary, result.summary.get("pool"),
                          result.summary.get("dedicated"))
        _print_summary(out, result, medians, args.trace, device_report,
                       shown=printer.shown if printer else 0, absent=absent,
                       no_user=args.no_user, definitions=package.metrics)
        _print_monitors(out, monitors)
    trace_lost = sink is not None and sink.failure is not None
    if sink is not None and sink.truncated is not None:      # the cap, or a full disk
        print(f"opspec run: {'error' if trace_lost else 'note'}: {sink.message()} "
              f"({sink.dropped:,} not written)", file=sys.stderr)
    device_faults = any(info.get("faults") for info in (device_report or {}).values())
    summary = result.summary
    problems = bool(_real_deadlocks(result, absent) or summary.get("faults")
                    or summary.get("instances", {}).get("aborted", 0) > len(absent))
    return 1 if problems or device_faults or trace_lost else 0


def _waiting_for_absent_user(summary: dict[str, Any], compiled: Any, user: Any
                             ) -> list[dict[str, Any]]:
    """The deadlocks that only say nobody performed the user lane, when nobody was meant to
    (``--no-user``, or no user model): an instance stopped at the end because every activity
    it waits on is a user-lane activity waiting for its performer. A device waiting for a user
    who is absent by choice is the expected end of a devices-only run, not a problem."""
    if getattr(user, "kind", None) != "none":
        return []
    from opspec.engine.lanes import all_activities

    user_acts = {(a.process, a.id) for a in all_activities(compiled) if a.user_lane}
    absent = []
    for deadlock in summary.get("deadlocks") or []:
        waiting = deadlock.get("waiting") or []
        if waiting and all(
                (deadlock.get("process"), item.split(" (", 1)[0]) in user_acts
                and " (performer for " in item for item in waiting):
            absent.append(deadlock)
    return absent


def _refuse_trace_over_input(args: argparse.Namespace, package: Any) -> None:
    """``--trace`` may not name a file this run reads (exit 2, both named)."""
    from opspec.commands._files import refuse_overwrite, spec_inputs
    from opspec.commands._spec import companion_user_model

    reads = [("SPEC", args.spec), ("--script", args.script),
             ("--user-model", args.user_model if args.user_model and Path(
                 args.user_model).exists() else None),
             ("the companion user model", companion_user_model(args.spec)),
             ("--engine-config", args.engine_config), *spec_inputs(args.spec, package)]
    refuse_overwrite([("--trace", args.trace)], reads)


def _real_deadlocks(result: RunResult, absent: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [d for d in result.summary.get("deadlocks") or [] if d not in absent]


def _absent_note(absent: list[dict[str, Any]], no_user: bool) -> str:
    """One line for every user-lane instance left waiting for the absent user."""
    processes = sorted({str(d.get("process")) for d in absent})
    activities = sorted({item.split(" (", 1)[0] for d in absent for item in d["waiting"]})
    why = "--no-user" if no_user else "no user model"
    return (f"nobody performed the user lane ({why}): {len(absent)} instance(s) of "
            f"{', '.join(processes)} were left waiting for the user at "
            f"{', '.join(activities)}, as expected without a user (not a deadlock)")


#: violations listed per monitor (all are counted)
MONITOR_SHOWN = 5


def _print_monitors(out: Any, monitors: dict[str, Any]) -> None:
    """The spec's monitors (``opspec:Monitor``): how often each was violated, the first few."""
    for text, result in monitors.items():
        if not result.count:
            print(f"monitor {text}: no violation", file=out)
            continue
        print(f"monitor {text}: {result.count} violation(s)", file=out)
        for violation in result.violations[:MONITOR_SHOWN]:
            print(f"  {clock_time(violation.time)}: {violation.message}", file=out)
        if result.count > MONITOR_SHOWN:
            print(f"  … and {result.count - MONITOR_SHOWN} more", file=out)


# ---------------------------------------------------------------------------- options


def _config(args: argparse.Namespace) -> Any:
    from opspec.engine.config import EngineConfig

    if args.engine_config:
        from opspec.commands._files import check_nesting

        check_nesting(args.engine_config, "the engine configuration")
    config = EngineConfig.load(args.engine_config) if args.engine_config else EngineConfig()
    overrides: dict[str, Any] = {}
    if args.processor_model:
        overrides["processor_model"] = args.processor_model
    if args.workers is not None:
        overrides["workers"] = args.workers
    if args.switch_cost is not None:
        overrides["switch_cost"] = args.switch_cost
    model = overrides.get("processor_model", config.processor_model)
    if args.queue_workers is not None:
        if model != "priority-queues":
            raise ConfigurationError("--queue-workers applies to the priority-queues model "
                                     "only", hint="add --processor-model priority-queues")
        overrides["queue_workers"] = args.queue_workers
    if model == "dedicated" and (args.workers is not None or args.switch_cost is not None):
        raise ConfigurationError(
            f"{'--workers' if args.workers is not None else '--switch-cost'} applies to the "
            "shared-processor models only; the dedicated model gives every workflow "
            "instance its own worker (unlimited processors, no switch cost, by design)",
            hint="add --processor-model pooled (or preemptive) to compare N shared processors")
    if args.speed is not None and not (args.realtime or config.realtime or args.bind):
        raise ConfigurationError("--speed only applies with --realtime",
                                 hint="add --realtime, or drop --speed")
    if args.realtime:
        overrides["realtime"] = True
        overrides["speed"] = args.speed if args.speed is not None else 1.0
    return config.with_options(**overrides) if overrides else config


def _devices(args: argparse.Namespace, stack: contextlib.ExitStack, compiled: Any) -> Any:
    if not args.bind:
        return None
    try:
        from opspec.bindings.attach import attach_devices
    except ImportError:
        raise ConfigurationError("--bind is not available in this build of opspec") from None
    return stack.enter_context(attach_devices(args.bind, args.devices, spec=compiled))


@contextlib.contextmanager
def _open_sink(factory: Any, path: str, header: dict[str, Any]) -> Iterator[Any]:
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        sink = factory(path, header)
    except OSError as error:
        from opspec.commands._files import write_problem

        raise ConfigurationError(write_problem(Path(path), error).replace(
            "cannot write ", "cannot write the trace ", 1),
            hint="choose a writable path with --trace") from None
    try:
        yield sink
    finally:
        sink.close()


# ---------------------------------------------------------------------------- output


def timeline_line(event: TraceEvent, lanes: Any = None) -> str:
    """One readable line: :func:`opspec.engine.trace_text.timeline_line` (``lanes``: the
    spec's :func:`opspec.engine.lane_labels.lane_labels`, for its lane names and widths)."""
    from opspec.engine.trace_text import timeline_line as line

    return line(event) if lanes is None else line(event, lanes)


def _lane_labels(compiled: Any) -> Any:
    from opspec.engine.lane_labels import lane_labels

    return lane_labels(compiled)


def _timeline(args: argparse.Namespace, compiled: Any, out: Any) -> Any:
    """The timeline printer the options ask for (None: no timeline)."""
    from opspec.commands.run_timeline import AllTimeline, BriefTimeline

    if args.json or args.timeline == "none":
        return None
    if args.timeline == "all":
        return AllTimeline(out, _lane_labels(compiled))
    return BriefTimeline(out, compiled, _lane_labels(compiled))


def json_metrics(metrics: dict[str, dict[str, Any]],
                 medians: dict[str, float] | None = None) -> dict[str, dict[str, Any]]:
    """The run's metrics in the shape of ``opspec evaluate --json`` for one replication:
    counts with ``total``; durations with ``mean``, ``median``, ``p95``, ``n``; ratios with
    ``value``."""
    out: dict[str, dict[str, Any]] = {}
    for name, value in metrics.items():
        kind = value.get("kind")
        if kind == "count":
            out[name] = {"kind": "count", "total": value.get("total", 0)}
        elif kind == "duration":
            out[name] = {"kind": "duration", "mean": value.get("mean"),
                         "median": (medians or {}).get(name), "p95": value.get("p95"),
                         "n": value.get("n", 0), "min": value.get("min"),
                         "max": value.get("max")}
        else:
            out[name] = dict(value)
    return out


def _json_document(args: argparse.Namespace, package: Any, horizon: float | None,
                   result: RunResult, devices: dict[str, Any] | None,
                   medians: dict[str, float]) -> dict[str, Any]:
    summary = result.summary
    doc: dict[str, Any] = {
        "spec": str(args.spec), "package": package.id, "seed": args.seed,
        "days": args.days, "until": horizon, "time": summary.get("time"),
        "metrics": json_metrics(result.metrics, medians),
        "instances": summary.get("instances"), "events": summary.get("events"),
        "deadlocks": [d.get("message") for d in summary.get("deadlocks") or []],
        "faults": [f.get("message") for f in summary.get("faults") or []],
        "trace": args.trace,
    }
    if summary.get("drift"):
        doc["drift"] = summary["drift"]
    if summary.get("pool"):
        doc["pool"] = summary["pool"]
    if args.timing and summary.get("dedicated"):
        doc["dedicated"] = summary["dedicated"]
    if devices is not None:
        doc["devices"] = devices
    return doc


def _percent(rate: Any, ci: list[Any]) -> str:
    """A miss rate with its exact 95 % interval, in percent."""
    if rate is None:
        return "-"
    return f"{100 * rate:.3g} [{100 * ci[0]:.3g}, {100 * ci[1]:.3g}]"


def _ms(value: Any) -> str:
    return "-" if value is None else f"{value * 1000:.2f}"


def _quantile_ms(t: dict[str, Any], name: str) -> str:
    """A response percentile in ms with its distribution-free 95 % interval (``?``: a bound
    too few instances cannot give)."""
    value = t.get(f"{name}_s")
    if value is None:
        return "-"
    low, high = t.get(f"{name}_ci_s") or (None, None)
    return (f"{value * 1000:.2f} [{'?' if low is None else f'{low * 1000:.2f}'}, "
            f"{'?' if high is None else f'{high * 1000:.2f}'}]")


def _print_timing(out: Any, timing: dict[str, dict[str, Any]], pool: dict[str, Any] | None,
                  dedicated: dict[str, Any] | None = None) -> None:
    wall = any(t.get("clock") == "wall" for t in timing.values())
    clock = "wall-clock" if wall else "simulated"
    print(f"\ntiming (times in milliseconds of {clock} time; percentiles with their "
          "distribution-free 95 % interval, ? where too few instances give no such bound; "
          "misses: instances past their deadline, with the miss rate's exact 95 % interval)",
          file=out)
    print(f"  {'workflow':<20}{'started':>8}{'done':>8}{'misses':>8}{'miss % [95 % CI]':>24}"
          f"{'mean ms':>10}{'max ms':>10}{'jitter ms':>11}", file=out)
    for name, t in timing.items():
        print(f"  {name:<20}{t['started']:>8}{t['completed']:>8}{t['misses']:>8}"
              f"{_percent(t.get('miss_rate'), t.get('miss_rate_ci') or [0, 0]):>24}"
              f"{_ms(t['response_mean_s']):>10}{_ms(t['response_max_s']):>10}"
              f"{_ms(t['jitter_s']):>11}", file=out)
        print(f"  {'':<20}p50 {_quantile_ms(t, 'response_p50')}  "
              f"p90 {_quantile_ms(t, 'response_p90')}  p99 {_quantile_ms(t, 'response_p99')}",
              file=out)
        if wall and t.get("start_late_max_s") is not None:
            print(f"  {'':<20}start late vs due (wall clock): mean "
                  f"{_ms(t['start_late_mean_s'])}, p99 {_ms(t['start_late_p99_s'])}, max "
                  f"{_ms(t['start_late_max_s'])} ms", file=out)
    model = (pool or {}).get("model")
    if pool and model == "priority-queues":
        print(f"  priority-queues model: {pool.get('cpus')} processor(s), "
              f"{pool.get('queue_workers')} worker(s) per queue, {pool.get('switches')} context "
              f"switches ({pool.get('leader_passes')} into the leader), "
              f"{pool.get('preemptions')} preemption(s), busy {figure(pool.get('busy_time'))} s, "
              f"at most {pool.get('max_waiting')} waiting", file=out)
    elif pool and pool.get("preemptive"):
        print(f"  preemptive model: {pool.get('workers')} processor(s), {pool.get('switches')} "
              f"dispatches, {pool.get('preemptions')} preemption(s), busy "
              f"{figure(pool.get('busy_time'))} s, at most {pool.get('max_waiting')} waiting",
              file=out)
    elif pool:
        print(f"  pooled model: {pool.get('workers')} worker(s), {pool.get('switches')} context "
              f"switches, busy {figure(pool.get('busy_time'))} s, at most "
              f"{pool.get('max_waiting')} waiting", file=out)
    elif dedicated:
        print("  dedicated model: one worker per workflow instance (unlimited processors, no "
              "switch cost, by design)", file=out)
        print(f"  {dedicated.get('bursts')} CPU bursts, busy {figure(dedicated.get('busy_time'))}"
              f" s, at most {dedicated.get('max_busy')} at once (pooled with that many workers "
              "and no switch cost waits for none)", file=out)
    print("  response = completion - start of an instance: declared durations count too"
          + ("; jitter = max - min start lateness" if wall else ""), file=out)


def _print_summary(out: Any, result: RunResult, medians: dict[str, float], trace: str | None,
                   devices: dict[str, Any] | None, *, shown: int,
                   absent: list[dict[str, Any]] | None = None, no_user: bool = False,
                   definitions: Iterable[MetricDefinition] = ()) -> None:
    """The text summary after the timeline: the spec's metrics (``definitions``: the spec's,
    for a ratio's numerator and denominator; :mod:`opspec.evaluation.run_metrics_text`), how
    the run ended, drift, devices, problems, the trace file."""
    from opspec.evaluation.run_metrics_text import metric_lines

    summary = result.summary
    print(file=out)
    lines = metric_lines(result.metrics, medians, definitions)
    if lines:
        print("metrics", *lines, sep="\n", file=out)
    counts = summary.get("instances", {})
    parts = ", ".join(f"{k} {v}" for k, v in counts.items() if v)
    # simulation events do not depend on the options; trace events are only those some
    # listener (timeline, --trace, --timing, metrics) asked for
    print(f"ended at {clock_time(summary.get('time', 0.0))}: {summary.get('sim_events', 0)} "
          f"simulation events, {summary.get('events', 0)} traced ({shown} shown), "
          f"instances: {parts or 'none'}", file=out)
    drift = summary.get("drift")
    if drift:
        print(f"wall-clock drift: mean {drift.get('mean_s', 0) * 1000:.2f} ms, "
              f"max {drift.get('max_s', 0) * 1000:.2f} ms over {drift.get('events', 0)} "
              "events", file=out)
    if devices:
        from opspec.commands.devices_summary import device_lines

        for line in device_lines(devices):
            print(line, file=out)
    if absent:
        print(_absent_note(absent, no_user), file=out)
    for problem in _real_deadlocks(result, absent or []):
        print(f"deadlock: {problem.get('message')}", file=out)
    for fault in summary.get("faults") or []:
        print(f"fault: {fault.get('message')}", file=out)
    if trace:
        print(f"trace: {trace}", file=out)
