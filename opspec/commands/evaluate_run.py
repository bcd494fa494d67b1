"""Running ``opspec evaluate`` once its drawing processes have started: a new run's plan or
a stored run to finish (``--resume``) opened with its results database, the replications,
the summaries and the report, then what the command prints (:mod:`.evaluate_output`)."""
from __future__ import annotations

import argparse
import contextlib
import math
import sys
from pathlib import Path
from typing import Any

from opspec.commands.evaluate_exports import export_estimate, trace_writers
from opspec.commands.evaluate_output import Results, print_results, replication_counts
from opspec.commands.evaluate_plan import (
    check_plan,
    claim_default_out,
    default_out,
    new_plan,
    refuse_earlier_outputs,
    refuse_file_out,
    refuse_inputs_in_out,
    refuse_spec_template,
)
from opspec.commands.evaluate_resume import check_unchanged, resume_differences, store_parameters
from opspec.errors import EvaluationError, OpspecError

__all__ = ["evaluate", "with_resume_hint"]


def evaluate(args: argparse.Namespace, workers: int, cores: int) -> int:
    """:func:`opspec.commands.evaluate.run` with the drawing processes started (``cores``:
    the cores this process may run on): the plan, the replications, the report."""
    if getattr(args, "report_template", None):   # read after the runs: refuse a bad one now
        from opspec.files import open_regular, reason

        refuse_spec_template(args)
        try:
            open_regular(args.report_template).close()
        except OSError as error:
            raise EvaluationError(f"cannot read the report template {args.report_template}: "
                                  f"{reason(error)}") from None
        from opspec.evaluation.html import prepare_template

        # compiled now: a syntax error is said (file:line) before the run, not after it
        prepare_template(args.report_template)
    from opspec.evaluation.runner import WORKER_TIMEOUT

    timeout = args.scheduler_timeout if args.scheduler_timeout is not None else WORKER_TIMEOUT
    if not (timeout > 0 and math.isfinite(timeout)):
        raise EvaluationError(f"--scheduler-timeout must be a positive number of seconds, "
                              f"not {timeout:g}")
    if args.scheduler:
        from opspec.evaluation.runner import check_scheduler

        check_scheduler(args.scheduler, timeout)
    opened = _resume(args) if args.resume else _start(args)
    if opened is None:                      # --sweep list: the parameters are printed
        return 0
    store, plan, swept = opened
    results = _replicate(args, store, plan, swept, workers, cores, timeout)
    print_results(args, plan, store, workers, results)
    from opspec.evaluation.memory import release_free_memory

    # what the run left to the collector and the allocator grows with the users: give it
    # back, so that the process (a notebook's, a service's) holds after the run what it uses
    # (the run's garbage was collected as startup_frozen ended)
    release_free_memory(collect=False)
    return 1 if results.failures else 0


def _resume(args: argparse.Namespace) -> tuple[Any, Any, Any]:
    """The stored run in ``--out``, its plan and sweep, checked against the options and
    files given now (the store is closed again when they differ)."""
    from opspec.evaluation.plan import EvaluationPlan
    from opspec.evaluation.store import ResultStore

    if not args.out:
        raise EvaluationError("--resume needs --out DIR (the folder of the run to finish)")
    refuse_file_out(Path(args.out))
    store = ResultStore(args.out, create=False)
    plan = EvaluationPlan.from_json(store.get("plan"))
    differs = resume_differences(args, plan)
    if differs:
        store.close()
        raise EvaluationError(
            f"{args.out} holds a run with other options; cannot resume it with "
            + "; ".join(differs),
            hint="resume with the stored options (or none: `opspec evaluate --resume "
            f"--out {args.out}`), or start a new run with another --out")
    check_unchanged(store, plan)
    definitions = check_plan(plan)     # the specs' warnings, as a new run shows them
    try:
        refuse_inputs_in_out(args, plan, store.folder)
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
            export_estimate(plan, store.folder, quiet=args.quiet)
        except EvaluationError:
            store.close()
            raise
    return store, plan, swept


def _start(args: argparse.Namespace) -> tuple[Any, Any, Any] | None:
    """A new run: its plan (a sweep's designs), checked, and its results database created
    with the run's parameters; ``None`` for ``--sweep list``, which prints the parameters."""
    from opspec import __version__
    from opspec.evaluation.store import ResultStore

    plan, decided = new_plan(args)
    swept = None
    if args.sweep:
        from opspec.evaluation.sweep import describe_parameters, plan_sweep

        if args.sweep[0] == "list":
            print(describe_parameters(plan))
            return None
        plan, swept = plan_sweep(plan, *args.sweep)
    definitions = check_plan(plan, decided)
    if args.target or args.target_users is not None or swept is not None:
        from opspec.evaluation.sweep import check_targets

        check_targets(args.target, args.target_users, definitions["A"], swept)
    out = Path(args.out) if args.out else default_out(args.spec)
    if args.out:
        refuse_file_out(out)
    if args.out and (out / "results.sqlite").exists():
        raise EvaluationError(f"{out} already holds an evaluation",
                              hint="add --resume to finish it, or choose another --out")
    refuse_inputs_in_out(args, plan, out)
    if args.out:
        refuse_earlier_outputs(out)
    if plan.export:                     # before anything is created
        export_estimate(plan, out, quiet=args.quiet)
    if not args.out:                    # the default folder: this run's own
        out = claim_default_out(out)
    store = ResultStore(out, create=True, new=True)
    store_parameters(store, plan, definitions, __version__)
    if swept is not None:
        store.put("sweep", swept.to_json())
    return store, plan, swept


def _replicate(args: argparse.Namespace, store: Any, plan: Any, swept: Any, workers: int,
               cores: int, timeout: float) -> Results:
    """Run the replications ``store`` does not hold yet, summarise them and write the
    report; the store is closed at the end."""
    from opspec.evaluation.memory import startup_frozen
    from opspec.evaluation.progress import make_progress
    from opspec.evaluation.runner import run_evaluation

    figures = getattr(args, "figures", "svg")
    drawing = min(workers, cores)  # the figures drawn side by side, as the users were
    ahead: list[Any] = []

    def ask_ahead() -> None:
        # the report's figures that read neither the sample index nor the summaries, drawn
        # while this process builds them (a core is idle otherwise)
        from opspec.evaluation.report import ask_figures_ahead

        ahead.append(ask_figures_ahead(store, figures=figures, workers=drawing))

    def prepare() -> None:
        from opspec.evaluation.report import prepare_report

        prepare_report(getattr(args, "report_template", None))

    # what is loaded by now lives through the run: the collector need not scan it again
    with store, contextlib.ExitStack() as stack, startup_frozen():
        on_trace = trace_writers(stack, store.folder, plan)
        progress = make_progress(sys.stderr, quiet=args.quiet or args.json,
                                 label="users" if len(plan.designs) == 1 else "replications")
        try:
            outcome = run_evaluation(plan, store, workers=workers, scheduler=args.scheduler,
                                     progress=progress, on_trace=on_trace,
                                     retrace=bool(args.resume and plan.export),
                                     scheduler_timeout=timeout,
                                     on_stored=ask_ahead if drawing > 1 else None,
                                     meanwhile=prepare)
            stack.close()                   # the exports are finished and moved into place
        except EvaluationError as error:
            raise with_resume_hint(error, store, plan) from None
        except KeyboardInterrupt:
            _say_stopped(store, plan)
            raise
        try:
            summaries, compare = _summarise(args, store, plan, swept)
            report = _write_report(args, store, plan, summaries, figures, drawing, ahead)
        except KeyboardInterrupt:
            # every replication is stored: only the report is missing (or half drawn)
            _say_stopped(store, plan, report=True)
            raise
        failures = store.failures()
        return Results(summaries, compare, report, outcome, failures,
                       replication_counts(store, plan, failures),
                       {key: store.get(key) for key in ("user_model_sha256",
                                                        "opspec_version")})


def _write_report(args: argparse.Namespace, store: Any, plan: Any, summaries: Any,
                  figures: str, drawing: int, ahead: list[Any]) -> Any:
    """The report of the stored run; what stops it is an error that says the results are
    stored and how to write the report again."""
    from opspec.evaluation.report import write_report

    try:
        return write_report(store, summaries, template=getattr(args, "report_template", None),
                            figures=figures, workers=drawing,
                            ahead=ahead[0] if ahead else None)
    except EvaluationError as error:
        raise with_resume_hint(error, store, plan) from None
    except OSError as error:
        raise EvaluationError(
            f"{store.folder}: cannot write the report: {error.strerror or error}",
            hint="the results are stored; free some space and run `opspec evaluate "
            f"--resume --out {store.folder}` to write the report again") from None


def _say_stopped(store: Any, plan: Any, *, report: bool = False) -> None:
    """Ctrl-C: what is kept, and the command that goes on from there. ``report``: stopped
    while the report was drawn; a run stopped once its last replication was stored is told
    the same (only the report is missing). The users of --input-uncertainty's parameter
    draws are replications too (stored as ``A~draws``), as the progress line counts them."""
    from opspec.evaluation.input_uncertainty import draws_label

    labels = [d.label for d in plan.designs]
    if plan.input_uncertainty:
        labels += [draws_label(label) for label in labels]
    stored = sum(len(store.finished(label)) for label in labels)
    planned = (plan.users + plan.input_uncertainty * plan.users_per_draw) * len(plan.designs)
    then = ("the report is not written; write it with" if report or stored >= planned
            else "finish with")
    print(f"opspec evaluate: stopped; {stored} of {planned} replications are stored in "
          f"{store.path}; {then} `opspec evaluate --resume --out {store.folder}`",
          file=sys.stderr)


def _summarise(args: argparse.Namespace, store: Any, plan: Any, swept: Any
               ) -> tuple[dict[str, dict[str, Any]], dict[str, Any] | None]:
    """The summaries of the stored replications, by design (plus ``sweep``), and the
    comparison of two designs (``None`` for one)."""
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
    return summaries, compare


def with_resume_hint(error: EvaluationError, store: Any, plan: Any) -> EvaluationError:
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
