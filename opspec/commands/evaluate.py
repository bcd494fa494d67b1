"""Evaluate a spec with many simulated users; report with CIs and plots.

Run SPEC for N simulated users x D days (each user an independent replication with their own
random streams), store every result in OUT/results.sqlite as it finishes, and write
OUT/report.html with metrics, confidence intervals and plots. The same seed gives the same
results whatever the number of workers (docs/evaluation.md).

Exit status: 0 every replication finished; 1 some failed (listed; --resume runs them again) or
the spec is broken; 2 usage, configuration or I/O errors.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from opspec.commands import _args
from opspec.errors import EvaluationError, OpspecError

__all__ = ["register", "run"]

EXPORTS = ("xes", "jsonl", "ocel")
#: the file each export format writes, in the output folder
EXPORT_FILES = {"xes": "traces.xes", "jsonl": "traces.jsonl", "ocel": "traces.jsonocel"}
DEFAULT_USERS = 100
DEFAULT_SEED = 0


def register(subparsers: Any) -> None:
    parser = _args.command(subparsers, "evaluate", __doc__)
    _args.add_spec(parser, optional="with --resume")
    parser.add_argument("--users", type=int, default=None,
                        help=f"simulated users (default {DEFAULT_USERS})")
    _args.add_days(parser, what=" per user")
    _args.add_seed(parser, default=None)
    _args.add_user_model(parser)
    parser.add_argument("--compare", metavar="SPEC2",
                        help="a second design, run on the same simulated users")
    _args.add_run_inputs(parser, per_user=True)
    parser.add_argument("--sweep", type=_args.sweep, metavar="PARAM=V1,V2,...",
                        help="run one design per value of a spec or user-model parameter, "
                        "on the same simulated users ('--sweep list' lists the parameters; "
                        "docs/evaluation.md, Sweeps)")
    parser.add_argument("--target", action="append", default=[], metavar="'METRIC OP VALUE'",
                        help="with --sweep: the values that meet it, e.g. 'missed_rate < 1%%' "
                        "(repeatable)")
    parser.add_argument("--target-users", type=_args.share, metavar="SHARE",
                        help="with --target: judge each user's own value, and ask that this "
                        "share of users (e.g. 95%%) meets the target")
    parser.add_argument("--input-uncertainty", type=int, default=None, metavar="B",
                        help="also run B parameter draws of a model fitted by `opspec fit`, "
                        "each on users of its own, and report each metric's interval with "
                        "the fitted parameters' uncertainty (docs/evaluation.md, Input "
                        "uncertainty)")
    parser.add_argument("--users-per-draw", type=int, default=None, metavar="M",
                        help="with --input-uncertainty: users per parameter draw (default: "
                        "--users / B, at least 10)")
    _args.add_engine_config(parser)
    parser.add_argument("--workers", type=int, default=None,
                        help="worker processes (default: all local cores)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on an existing Dask distributed cluster (tcp://host:8786)")
    parser.add_argument("--scheduler-timeout", type=float, default=None, metavar="SECONDS",
                        help="with --scheduler: how long to wait for the cluster to have a "
                        "worker, at the start and whenever all have left (default 60)")
    parser.add_argument("--out", metavar="DIR",
                        help="output folder (default: runs/<spec>-<date-time>)")
    parser.add_argument("--resume", action="store_true",
                        help="finish the evaluation stored in --out (missing or failed users)")
    parser.add_argument("--export", action="append", default=[], metavar="FMT",
                        help="also write traces: xes (traces.xes), jsonl (traces.jsonl), "
                        "ocel (traces.jsonocel, OCEL 2.0); repeatable or comma-separated")
    parser.add_argument("--case", choices=("chain", "user", "instance", "dose"), default=None,
                        help="what one case of the xes and jsonl exports is: chain (the "
                        "default: a root device workflow's run and everything it set in "
                        "motion, named after that workflow; 'dose' is an earlier name), a "
                        "simulated user's whole run, or one workflow instance "
                        "(docs/xes-export.md)")
    parser.add_argument("--figures", choices=("svg", "pdf", "png"), default="svg",
                        help="the format of the report's figures in OUT/figures/: svg "
                        "(vector, the default), pdf (vector, for LaTeX; SVG twins beside them "
                        "for the HTML report) or png (200 dpi); the HTML report inlines SVG")
    _args.add_json(parser, "one JSON object with the results (docs/evaluation.md)")
    parser.add_argument("--quiet", action="store_true", help="no progress output")
    parser.add_argument("--report-template", metavar="FILE",
                        help="a Jinja2 template for report.html (start from a copy of "
                        "opspec/evaluation/templates/report.html.j2). A template is code: it "
                        "runs sandboxed, and one in the spec's own folder (it may have come "
                        "with the spec) is refused unless --trust-spec-template is given")
    parser.add_argument("--trust-spec-template", action="store_true",
                        help="allow a --report-template that lies in the spec's folder")
    parser.set_defaults(handler=run)


def _exports(values: list[str]) -> tuple[str, ...]:
    formats: list[str] = []
    for value in values:
        for part in value.split(","):
            fmt = part.strip().lower()
            if fmt not in EXPORTS:
                raise EvaluationError(f"--export {part!r} is not a known format",
                                      hint=f"choose from: {', '.join(EXPORTS)}")
            if fmt not in formats:
                formats.append(fmt)
    return tuple(formats)


def _local_cores() -> int:
    """The cores this process may run on (a container or taskset may allow fewer than the
    machine has)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def _default_out(spec: str) -> Path:
    stem = Path(spec).name.split(".")[0]
    stamp = datetime.now(UTC).strftime("%Y%m%d-%H%M%S")
    return Path("runs") / f"{stem}-{stamp}"


def _engine(path: str | None) -> dict[str, Any]:
    if path is None:
        return {}
    from opspec.commands._files import check_nesting
    from opspec.engine.config import EngineConfig

    check_nesting(path, "the engine configuration")
    return asdict(EngineConfig.load(path))


def _new_plan(args: argparse.Namespace) -> tuple[Any, dict[str, Any]]:
    """The plan of a new run, and the front hall's decision on each design's spec and the
    user model (:func:`_check_plan` reuses them: nothing is read and checked twice)."""
    from opspec.evaluation.plan import DAY, Design, EvaluationPlan, file_digest
    from opspec.request import RunRequest, prepare
    from opspec.run_inputs import RunInputs
    from opspec.run_rules import check_days

    if args.spec is None:
        raise EvaluationError("give the SPEC to evaluate (or --resume --out DIR)")
    if args.days is not None:
        check_days(args.days, name="--days")
    specs = [("A", args.spec)] + ([("B", args.compare)] if args.compare else [])
    # each design fills the request of every door: a spec validate rejects stops here
    # (path:line); design A decides the run length and the user model of both
    from opspec.branch_choices import parse_branch_options

    branches = parse_branch_options(args.branch)
    a = prepare(RunRequest(args.spec, days=args.days, user_model=args.user_model,
                           branches=branches or None))
    model = a.user_model
    decided = {str(args.spec): a}
    for _label, path in specs[1:]:
        b = prepare(RunRequest(path, days=args.days, user_model=model, no_user=model is None,
                               branches=branches or None))
        decided.setdefault(str(path), b)
    # --param: a value of a package data field (a BPMN diagram's run input) for every design,
    # applied as a parameter of one value (what --sweep applies per design)
    # draws and a data file's rows are per simulated user (opspec.run_inputs), in the plan
    from opspec.commands._params import read_run_inputs

    inputs = read_run_inputs(args.param, args.params, a.package)
    fixed = tuple((f"spec.{name}", value) for name, value in inputs.values)
    designs = [Design(label, str(path), file_digest(path), fixed) for label, path in specs]
    days = float(args.days) if args.days is not None else a.horizon / DAY
    users = args.users if args.users is not None else (len(inputs.rows) or DEFAULT_USERS)
    if inputs.rows and users > len(inputs.rows):
        raise EvaluationError(f"--users {users}: {args.params} has {len(inputs.rows)} rows, "
                              "one per simulated user", hint=f"give --users {len(inputs.rows)} "
                              "or fewer, or add rows")
    per_user = [n for n, _t, _i in inputs.draws] + [n for row in inputs.rows for n in row]
    if args.sweep and args.sweep[0].removeprefix("spec.") in per_user:
        raise EvaluationError(f"--sweep {args.sweep[0]}: {args.sweep[0].removeprefix('spec.')} "
                              "is drawn per user (--param NAME~…) or read from --params, "
                              "which would override every swept value",
                              hint="sweep it, or draw it, not both")
    if (inputs.draws or inputs.rows) and args.input_uncertainty:
        raise EvaluationError("--input-uncertainty runs users of its own: it does not take "
                              "drawn run inputs or a data file's rows",
                              hint="give the run inputs values (--param NAME=VALUE)")
    run_seed = args.seed if args.seed is not None else DEFAULT_SEED
    export = _exports(args.export)
    if args.case is not None and not {"xes", "jsonl"} & set(export):
        raise EvaluationError(f"--case {args.case} applies to the xes and jsonl exports",
                              hint="add --export xes (or jsonl), or drop --case (OCEL "
                              "relates each event to every object instead of one case)")
    draws = args.input_uncertainty or 0
    if args.users_per_draw is not None and not draws:
        raise EvaluationError("--users-per-draw goes with --input-uncertainty B")
    per_draw = 0
    if draws:
        from opspec.evaluation.input_uncertainty import default_users_per_draw

        per_draw = (args.users_per_draw if args.users_per_draw is not None
                    else default_users_per_draw(users, draws))
    return EvaluationPlan(designs=tuple(designs), users=users, days=days,
                          seed=run_seed, user_model=model, engine=_engine(args.engine_config),
                          export=export, case=args.case or "chain",
                          input_uncertainty=draws, users_per_draw=per_draw,
                          run_inputs=RunInputs(draws=inputs.draws, rows=inputs.rows,
                                               source=inputs.source).to_json()
                          if inputs.draws or inputs.rows else {}, branches=branches), decided


def _check_plan(plan: Any, decided: dict[str, Any] | None = None
                ) -> dict[str, list[dict[str, Any]]]:
    """Load every design and the user model once, before any simulation: bad inputs stop the
    run here (``decided``: what :func:`_new_plan` read and checked already, by spec).
    Returns the metric definitions of each design, by label."""
    from opspec.evaluation.replication import prepare

    definitions: dict[str, list[dict[str, Any]]] = {}
    shown: set[str] = set()                 # the designs of a sweep share their warnings
    for design in plan.designs:
        context = prepare(design.spec, design.sha256, plan.user_model, plan.engine,
                          design.parameters, plan.branches or None,
                          decided=(decided or {}).get(design.spec))
        for warning in context.warnings:
            if str(warning) not in shown:
                shown.add(str(warning))
                print(f"opspec evaluate: {warning}", file=sys.stderr)
        from opspec.engine.lanes import user_lane

        if context.model is None and not user_lane(context.compiled).empty:
            from opspec.usermodels.loader import preset_names

            raise EvaluationError(
                f"{design.spec}: the spec has a user lane but no user model was given",
                hint="give --user-model FILE|PRESET (presets: "
                f"{', '.join(preset_names())}; docs/user-models.md) or put SPEC.users.toml "
                "next to the spec")
        from opspec.evaluation.describe import metric_record

        definitions[design.label] = [metric_record(m) for m in context.compiled.package.metrics]
    if plan.input_uncertainty:          # the fitted model's draws: there, and enough of them
        from opspec.evaluation.input_uncertainty import check_draws

        check_draws(plan)
    return definitions


def _user_model_digest(plan: Any) -> str | None:
    """SHA-256 of the user-model file (None for presets: they change with opspec itself)."""
    from opspec.evaluation.plan import file_digest

    if plan.user_model is None or not Path(plan.user_model).is_file():
        return None
    return file_digest(plan.user_model)


def _store_parameters(store: Any, plan: Any, definitions: dict[str, list[dict[str, Any]]],
                      version: str) -> None:
    """The ``run`` table: the plan (what ``--resume`` re-runs) and, as separate keys for
    readers of the database, the parameters it is made of."""
    a = plan.design("A")
    store.put("plan", plan.to_json())
    store.put("metrics", definitions["A"])
    for label, declared in definitions.items():
        if label != "A":
            store.put(f"metrics_{label}", declared)
    store.put("spec", a.spec)
    store.put("spec_sha256", a.sha256)
    store.put("designs", [{"label": d.label, "spec": d.spec, "sha256": d.sha256}
                          for d in plan.designs])
    store.put("users", plan.users)
    store.put("days", plan.days)
    store.put("seed", plan.seed)
    store.put("user_model", plan.user_model)
    store.put("user_model_sha256", _user_model_digest(plan))
    store.put("opspec_version", version)
    store.put("started", datetime.now(UTC).isoformat(timespec="seconds"))


def _same_file(given: str | None, stored: str | None) -> bool:
    """Whether two spellings name the same file (or preset): ``specs/a.xpdl`` and
    ``./specs/a.xpdl`` do."""
    if given is None or stored is None:
        return given == stored
    if given == stored:
        return True
    try:
        return Path(given).resolve() == Path(stored).resolve() and Path(given).exists()
    except OSError:
        return False


def _resume_differences(args: argparse.Namespace, plan: Any) -> list[str]:
    """Each option given with ``--resume`` that differs from the stored run, as
    ``--users 8 (stored: 4)``: resuming with them would silently mix two runs, or ignore
    what the user asked for. Options not given take the stored values."""
    differs: list[str] = []
    a = plan.design("A")
    if args.spec is not None and not _same_file(args.spec, a.spec):
        differs.append(f"SPEC {args.spec} (stored: {a.spec})")
    if args.users is not None and args.users != plan.users:
        differs.append(f"--users {args.users} (stored: {plan.users})")
    if args.days is not None and float(args.days) != float(plan.days):
        differs.append(f"--days {args.days:g} (stored: {plan.days:g})")
    if args.seed is not None and args.seed != plan.seed:
        differs.append(f"--seed {args.seed} (stored: {plan.seed})")
    if args.user_model is not None and not _same_file(args.user_model, plan.user_model):
        differs.append(f"--user-model {args.user_model} (stored: "
                       f"{plan.user_model or 'none'})")
    if args.compare is not None:
        b = next((d for d in plan.designs if d.label == "B"), None)
        if b is None or not _same_file(args.compare, b.spec):
            differs.append(f"--compare {args.compare} (stored: "
                           f"{b.spec if b is not None else 'no second design'})")
    if args.engine_config is not None:
        engine = _engine(args.engine_config)
        if json.dumps(engine, sort_keys=True) != json.dumps(dict(plan.engine), sort_keys=True):
            changed = sorted(k for k in set(engine) | set(plan.engine)
                             if engine.get(k) != plan.engine.get(k))
            differs.append(f"--engine-config {args.engine_config} ("
                           + ", ".join(f"{k} {engine.get(k)!r}, stored "
                                       f"{plan.engine.get(k)!r}" for k in changed[:4]) + ")")
    if args.export:
        export = _exports(args.export)
        if export != tuple(plan.export):
            differs.append(f"--export {','.join(export)} (stored: "
                           f"{','.join(plan.export) or 'none'})")
    if args.case is not None and args.case != plan.case:
        differs.append(f"--case {args.case} (stored: {plan.case})")
    if args.input_uncertainty is not None and args.input_uncertainty != plan.input_uncertainty:
        differs.append(f"--input-uncertainty {args.input_uncertainty} (stored: "
                       f"{plan.input_uncertainty or 'none'})")
    if args.users_per_draw is not None and args.users_per_draw != plan.users_per_draw:
        differs.append(f"--users-per-draw {args.users_per_draw} (stored: "
                       f"{plan.users_per_draw or 'none'})")
    return differs


def _check_unchanged(store: Any, plan: Any) -> None:
    """Refuse to resume when a spec or the user-model file changed since the run started:
    the finished and the remaining users would then describe different designs."""
    from opspec.evaluation.plan import file_digest

    changed = [f"{d.spec} changed since the run started (its content's SHA-256 is now "
               f"{file_digest(d.spec)[:12]}…, the stored run's {d.sha256[:12]}…)"
               for d in plan.designs if file_digest(d.spec) != d.sha256]
    stored_model = store.get("user_model_sha256")
    if stored_model is not None:
        now = _user_model_digest(plan)
        if now != stored_model:
            changed.append(f"{plan.user_model} changed since the run started (its content's "
                           f"SHA-256 is now {now[:12] + '…' if now else 'unreadable'}, the "
                           f"stored run's {stored_model[:12]}…)")
    if changed:
        store.close()
        raise EvaluationError(
            f"{store.folder}: cannot resume, {'; '.join(changed)}",
            hint="restore the files as they were, or start a new run with another --out")


def run(args: argparse.Namespace) -> int:
    workers = args.workers if args.workers is not None else _local_cores()
    if workers < 1:
        raise EvaluationError(f"--workers must be >= 1, not {workers}")
    from opspec.evaluation import plots

    # the report's drawing processes (--workers W > 1) start now: as many as the cores this
    # start-up leaves idle (it is the run's one serial part) import matplotlib while this
    # process loads and checks the specs and the user model; the others are forked once the
    # replications start (plots.staggered_start); a bad input ends them at once
    # (plots.drawing_processes), so its error comes as fast as before
    listing = bool(args.sweep) and args.sweep[0] == "list"
    cores = _local_cores()
    with plots.staggered_start(max(1, cores - 1)), \
            plots.drawing_processes(1 if listing else min(workers, cores)):
        return _evaluate(args, workers)


def _evaluate(args: argparse.Namespace, workers: int) -> int:
    """:func:`run` with the drawing processes started: the plan, the replications, the
    report."""
    from opspec import __version__
    from opspec.evaluation.plan import EvaluationPlan
    from opspec.evaluation.progress import make_progress
    from opspec.evaluation.runner import run_evaluation
    from opspec.evaluation.store import ResultStore

    if getattr(args, "report_template", None):   # read after the runs: refuse a bad one now
        from opspec.files import open_regular, reason

        _refuse_spec_template(args)
        try:
            open_regular(args.report_template).close()
        except OSError as error:
            raise EvaluationError(f"cannot read the report template {args.report_template}: "
                                  f"{reason(error)}") from None
    from opspec.evaluation.runner import WORKER_TIMEOUT

    timeout = args.scheduler_timeout if args.scheduler_timeout is not None else WORKER_TIMEOUT
    if not (timeout > 0 and math.isfinite(timeout)):
        raise EvaluationError(f"--scheduler-timeout must be a positive number of seconds, "
                              f"not {timeout:g}")
    if args.scheduler:
        from opspec.evaluation.runner import check_scheduler

        check_scheduler(args.scheduler, timeout)
    if args.resume:
        if not args.out:
            raise EvaluationError("--resume needs --out DIR (the folder of the run to finish)")
        store = ResultStore(args.out, create=False)
        plan = EvaluationPlan.from_json(store.get("plan"))
        differs = _resume_differences(args, plan)
        if differs:
            store.close()
            raise EvaluationError(
                f"{args.out} holds a run with other options; cannot resume it with "
                + "; ".join(differs),
                hint="resume with the stored options (or none: `opspec evaluate --resume "
                f"--out {args.out}`), or start a new run with another --out")
        _check_unchanged(store, plan)
        definitions = _check_plan(plan)     # the specs' warnings, as a new run shows them
        try:
            _refuse_inputs_in_out(args, plan, store.folder)
        except OpspecError:
            store.close()
            raise
        from opspec.evaluation.sweep import check_targets, resumed_sweep

        try:
            swept = resumed_sweep(store, plan, args.sweep)
            check_targets(args.target, args.target_users, definitions["A"], swept)
        except EvaluationError:
            store.close()
            raise
        if plan.export:
            try:
                _export_estimate(plan, store.folder, quiet=args.quiet)
            except EvaluationError:
                store.close()
                raise
    else:
        plan, decided = _new_plan(args)
        swept = None
        if args.sweep:
            from opspec.evaluation.sweep import describe_parameters, plan_sweep

            if args.sweep[0] == "list":
                print(describe_parameters(plan))
                return 0
            plan, swept = plan_sweep(plan, *args.sweep)
        definitions = _check_plan(plan, decided)
        if args.target or args.target_users is not None or swept is not None:
            from opspec.evaluation.sweep import check_targets

            check_targets(args.target, args.target_users, definitions["A"], swept)
        out = Path(args.out) if args.out else _default_out(args.spec)
        if (out / "results.sqlite").exists():
            raise EvaluationError(f"{out} already holds an evaluation",
                                  hint="add --resume to finish it, or choose another --out")
        _refuse_inputs_in_out(args, plan, out)
        if plan.export:                     # before anything is created
            _export_estimate(plan, out, quiet=args.quiet)
        store = ResultStore(out, create=True)
        _store_parameters(store, plan, definitions, __version__)
        if swept is not None:
            store.put("sweep", swept.to_json())
    from opspec.evaluation import plots
    from opspec.evaluation.memory import startup_frozen

    # what is loaded by now lives through the run: the collector need not scan it again
    with store, contextlib.ExitStack() as stack, startup_frozen():
        # the drawing processes not forked yet are forked now, inheriting what the start-up
        # loaded (frozen: their collector leaves it alone too), and import matplotlib beside
        # the replications, whose chunks share the cores
        plots.warm_up_the_rest()
        on_trace = _trace_writers(stack, store.folder, plan)
        progress = make_progress(sys.stderr, quiet=args.quiet or args.json,
                                 label="users" if len(plan.designs) == 1 else "replications")
        try:
            outcome = run_evaluation(plan, store, workers=workers, scheduler=args.scheduler,
                                     progress=progress, on_trace=on_trace,
                                     retrace=bool(args.resume and plan.export),
                                     scheduler_timeout=timeout)
            stack.close()                   # the exports are finished and moved into place
        except EvaluationError as error:
            raise _with_resume_hint(error, store, plan) from None
        except KeyboardInterrupt:
            stored = sum(len(store.finished(d.label)) for d in plan.designs)
            print(f"evaluate: stopped; {stored} of {plan.users * len(plan.designs)} "
                  f"replications are stored in {store.path}; finish with `opspec evaluate "
                  f"--resume --out {store.folder}`", file=sys.stderr)
            raise
        from opspec.evaluation.report import write_report
        from opspec.evaluation.summary import (
            compare_designs,
            summarise_design,
            summarise_monitors,
            summarise_population,
        )

        metrics = summarise_design(store, "A", plan.days)
        monitors = summarise_monitors(store, "A", plan.days)
        compare = None
        if any(d.label == "B" for d in plan.designs):
            compare = {"spec": plan.design("B").spec,
                       "metrics": summarise_design(store, "B", plan.days),
                       "monitors": summarise_monitors(store, "B", plan.days),
                       "difference": compare_designs(store)}
        # the report draws on the same summaries: nothing is computed twice
        summaries: dict[str, dict[str, Any]] = {"A": {"metrics": metrics, "monitors": monitors}}
        if compare is not None:
            summaries["B"] = {"metrics": compare["metrics"], "monitors": compare["monitors"],
                              "difference": compare["difference"]}
        # a population user model: who the users were, every metric per subgroup
        population = summarise_population(store, plan.days, designs=[
            d.label for d in plan.designs] if swept is None else ["A"])
        summaries["A"]["population"] = population
        from opspec.evaluation.input_uncertainty import summarise_input_uncertainty

        uncertainty = summarise_input_uncertainty(
            store, plan, metrics, compare=compare["difference"] if compare else None)
        summaries["A"]["input_uncertainty"] = uncertainty
        if swept is not None:               # per value, paired against the first; targets
            from opspec.evaluation.sweep import summarise_sweep

            summaries["sweep"] = summarise_sweep(store, swept, plan.days, args.target,
                                                 args.target_users)
        try:
            # the figures drawn side by side on this machine's cores, as the users were
            report = write_report(store, summaries,
                                  template=getattr(args, "report_template", None),
                                  figures=getattr(args, "figures", "svg"),
                                  workers=min(workers, _local_cores()))
        except EvaluationError as error:
            raise _with_resume_hint(error, store, plan) from None
        except OSError as error:
            raise EvaluationError(
                f"{store.folder}: cannot write the report: {error.strerror or error}",
                hint="the results are stored; free some space and run `opspec evaluate "
                f"--resume --out {store.folder}` to write the report again") from None
        failures = store.failures()
        counts = _replication_counts(store, plan, failures)
    from opspec.evaluation.failures import kind_of

    if args.json:
        doc = {"spec": plan.design("A").spec, "users": plan.users, "days": plan.days,
               "seed": plan.seed, "user_model": plan.user_model, "workers": workers,
               "scheduler": args.scheduler,
               "out": str(store.folder), "report": str(report), "metrics": metrics,
               "monitors": monitors, "population": population,
               "input_uncertainty": uncertainty,
               "replications": counts,
               "failed": [{"design": d, "user": u, "error": e, "kind": kind_of(e)}
                          for d, u, e in failures],
               "wall_s": round(outcome.wall_s, 3)}
        if compare is not None:
            doc["compare"] = compare
        if swept is not None:
            doc["sweep"] = summaries["sweep"]
        from opspec.statistics.methods import describe, methods_in

        # what every "ci95_method" above means: its recipe and references
        doc["interval_methods"] = describe(methods_in(doc))
        print(json.dumps(_finite(doc), allow_nan=False, default=str))
    else:
        from opspec.evaluation.tables import print_summary

        print_summary(sys.stdout, plan, metrics, compare, outcome, failures, workers,
                      monitors=monitors, population=population)
        from opspec.evaluation.input_uncertainty import print_input_uncertainty

        print_input_uncertainty(sys.stdout, uncertainty)
        if swept is not None:
            from opspec.evaluation.sweep import print_sweep

            print_sweep(sys.stdout, summaries["sweep"], plan.users)
        print(f"results: {store.path}\nreport: {report}")
    from opspec.evaluation.memory import release_free_memory

    # what the run left to the collector and the allocator grows with the users: give it
    # back, so that the process (a notebook's, a service's) holds after the run what it uses
    # (the run's garbage was collected as startup_frozen ended)
    release_free_memory(collect=False)
    return 1 if failures else 0


def _refuse_spec_template(args: argparse.Namespace) -> None:
    """A report template is code: one that lies in a spec's folder tree (it may have come
    with a spec from elsewhere) is used only when the user says so."""
    if getattr(args, "trust_spec_template", False):
        return
    template = Path(args.report_template)
    for option, spec in (("SPEC", args.spec), ("--compare", args.compare)):
        if not spec:
            continue
        try:
            inside = template.resolve().is_relative_to(Path(spec).resolve().parent)
        except (OSError, RuntimeError):
            inside = False
        if inside:
            raise EvaluationError(
                f"--report-template {template} lies in the folder of {option} {spec}; a "
                "template is code, and one that came with a spec is not used unless asked",
                hint="check the template, then add --trust-spec-template (or keep your "
                "templates in a folder of your own)")


#: what an evaluation writes into its output folder besides the exports and figures/
OUT_FILES = ("results.sqlite", "results.sqlite-wal", "results.sqlite-shm", "report.html",
             "report.md")


def _refuse_inputs_in_out(args: argparse.Namespace, plan: Any, out: Path) -> None:
    """No file the evaluation writes into ``out`` may be one it reads (exit 2, both
    named): a report template named ``OUT/report.html``, a spec in ``OUT/figures/``…"""
    from opspec.commands._files import refuse_overwrite, spec_inputs
    from opspec.evaluation.replication import prepare

    reads: list[Any] = []
    for design in plan.designs:
        what = "SPEC" if design.label == "A" else f"design {design.label}"
        reads.append((what, design.spec))
        # loaded once per process already (_check_plan): the same context, from its cache
        package = prepare(design.spec, design.sha256, plan.user_model, plan.engine,
                          design.parameters, plan.branches or None).compiled.package
        reads.extend(spec_inputs(design.spec, package))
    reads += [("--report-template", getattr(args, "report_template", None)),
              ("--engine-config", args.engine_config)]
    if plan.user_model and Path(plan.user_model).exists():
        reads.append(("the user model", plan.user_model))
    writes = [(f"--out {out}: {name}", out / name) for name in (
        *OUT_FILES, *(EXPORT_FILES[f] for f in plan.export),
        *(EXPORT_FILES[f] + ".partial" for f in plan.export))]
    refuse_overwrite("evaluate", writes, reads, folders=[(f"--out {out}", out / "figures")])


def _replication_counts(store: Any, plan: Any, failures: list[tuple[str, int, str]]
                        ) -> dict[str, Any]:
    """Replications planned, complete (what every number is computed from) and failed."""
    complete = {d.label: len(store.finished(d.label)) for d in plan.designs}
    return {"planned": plan.users * len(plan.designs), "complete": sum(complete.values()),
            "complete_by_design": complete,
            "failed": sum(1 for d, _, _ in failures if d in complete),
            "metrics_from": "complete replications only"}


def _with_resume_hint(error: EvaluationError, store: Any, plan: Any) -> EvaluationError:
    """``error`` (the run stopped part-way: a full disk, a cluster without workers) with
    how much is kept and the command that finishes the run, when it does not say so yet."""
    if "--resume" in (error.hint or ""):
        return error
    try:
        stored = sum(len(store.finished(d.label)) for d in plan.designs)
    except EvaluationError:
        stored = None
    kept = (f"{stored} of {plan.users * len(plan.designs)} replications are stored"
            if stored is not None else "every replication stored so far is kept")
    hint = (f"{error.hint}; " if error.hint else "") + (
        f"{kept}: `opspec evaluate --resume --out {store.folder}` finishes the run")
    return EvaluationError(error.message, hint=hint, location=error.location)


def _finite(value: Any) -> Any:
    """``value`` with NaN and infinities as ``null`` (JSON has no spelling for them)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value


def _writer(fmt: str, path: Path, plan: Any) -> Any:
    """The streaming writer of one export format."""
    from opspec.evaluation.exporters import JsonlTraceWriter, XesWriter

    attrs: dict[str, Any] = {"spec": plan.design("A").spec, "seed": plan.seed,
                             "case notion": plan.case}
    if fmt == "jsonl":
        return JsonlTraceWriter(path, log_attributes=attrs)
    from opspec.commands._spec import load_any_spec
    from opspec.engine.compiled import compile_package
    from opspec.engine.lane_labels import lane_labels
    from opspec.engine.lanes import user_lane
    from opspec.evaluation.ocel import OcelWriter, people_of

    package = load_any_spec(plan.design("A").spec)
    compiled = compile_package(package)
    # org:group names a lane as the timeline does: its name, its id where it has none
    lanes = lane_labels(compiled).names
    if fmt == "xes":
        return XesWriter(path, log_attributes=attrs, lane_names=lanes)
    people = people_of(package, user_lane(compiled).bind_names, compiled)
    return OcelWriter(path, people=people, lane_names=lanes)


def _trace_writers(stack: contextlib.ExitStack, folder: Path, plan: Any) -> Any:
    if not plan.export:
        return None
    from opspec.engine.trace import TraceEvent
    from opspec.evaluation.cases import split_cases

    # a resumed run simulates the stored users again for their traces (run_evaluation's
    # retrace), so each file is written whole again; the interrupted run's .partial goes
    cased: list[Any] = []
    whole: list[Any] = []
    for fmt in plan.export:
        writer = stack.enter_context(_writer(fmt, folder / EXPORT_FILES[fmt], plan))
        (whole if fmt == "ocel" else cased).append(writer)

    def write(record: Any) -> None:
        events = [TraceEvent.from_json(e) for e in record.trace]
        base = f"{record.design}/{record.user}"
        attributes = {"design": record.design, "user": record.user}
        if cased:
            for suffix, group in split_cases(events, plan.case):
                case_id = base if suffix is None else f"{base}/{suffix}"
                for writer in cased:
                    writer.add_case(case_id, group, attributes)
        for writer in whole:
            writer.add_case(base, events, attributes)

    return write


def _export_estimate(plan: Any, folder: Path, quiet: bool) -> None:
    """Say how large each export will be, before the run: one simulated user-day of user 0
    is exported to a scratch folder and scaled to every user and day. An estimate larger
    than the disk's free space, or than the trace cap, stops here (exit 2) instead of hours
    later."""
    import shutil
    import tempfile

    from opspec.engine.trace_sinks import TRACE_MAX_BYTES_ENV, trace_max_bytes
    from opspec.evaluation.plan import DAY
    from opspec.evaluation.replication import prepare, run_user

    design = plan.designs[0]
    context = prepare(design.spec, design.sha256, plan.user_model, plan.engine,
                      design.parameters, plan.branches or None)
    sample = min(plan.horizon, DAY)
    record = run_user(context, design.label, 0, seed=plan.seed, horizon=sample,
                      keep_trace=True)
    if record.trace is None:
        return
    scale = plan.users * len(plan.designs) * plan.horizon / sample
    sizes: dict[str, float] = {}
    try:
        with tempfile.TemporaryDirectory(prefix="opspec-estimate-") as scratch, \
                contextlib.ExitStack() as stack:
            write = _trace_writers(stack, Path(scratch), plan)
            write(record)
            stack.close()
            for fmt in plan.export:
                sizes[fmt] = (Path(scratch) / EXPORT_FILES[fmt]).stat().st_size * scale
    except (OSError, EvaluationError) as error:
        # the scratch folder (the system's temporary folder) is not the output's disk
        if not quiet:
            print(f"evaluate: the size of the export could not be estimated ({error})",
                  file=sys.stderr)
        return
    total = sum(sizes.values())
    span = f"{plan.users:,} user(s) x {plan.days:g} day(s)" + (
        f" x {len(plan.designs)} designs" if len(plan.designs) > 1 else "")
    if not quiet:
        for fmt, size in sizes.items():
            print(f"evaluate: {EXPORT_FILES[fmt]} will be about {_bytes(size)} ({span}; "
                  "estimated from one simulated user-day)", file=sys.stderr)
    cap = trace_max_bytes()
    over = [fmt for fmt, size in sizes.items() if size > cap]
    if over:
        raise EvaluationError(
            f"--export {','.join(over)}: {EXPORT_FILES[over[0]]} would be about "
            f"{_bytes(sizes[over[0]])}, past the trace cap of {_bytes(cap)}",
            hint=f"export fewer users or days, or set {TRACE_MAX_BYTES_ENV} to a larger "
            "number of bytes")
    where = folder
    while not where.exists() and where != where.parent:
        where = where.parent
    free = shutil.disk_usage(where).free
    if total > free:
        raise EvaluationError(
            f"--export needs about {_bytes(total)} in {folder}, and the disk has "
            f"{_bytes(free)} free", hint="free some space, export fewer users or days, or "
            "choose another --out")


def _bytes(size: float) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if size >= scale:
            return f"{size / scale:.3g} {unit}"
    return f"{size:.0f} bytes"
