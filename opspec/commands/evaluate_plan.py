"""A new evaluation's plan, from the options of ``opspec evaluate``, and the checks made
before any simulation: the designs (SPEC, ``--compare``), users, days, seed, run inputs and
exports (:func:`new_plan`); every design and the user model loaded once (:func:`check_plan`);
a report template that came with a spec, and an input the output folder would overwrite
(both refused)."""
from __future__ import annotations

import argparse
import contextlib
import sys
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from opspec.commands.evaluate_exports import EXPORT_FILES, export_formats
from opspec.errors import EvaluationError

__all__ = ["DEFAULT_SEED", "DEFAULT_USERS", "OUT_FILES", "check_plan", "claim_default_out",
           "default_out",
           "engine_settings", "new_plan", "refuse_earlier_outputs", "refuse_file_out",
           "refuse_inputs_in_out",
           "refuse_spec_template"]

DEFAULT_USERS = 100
DEFAULT_SEED = 0


def default_out(spec: str) -> Path:
    """The output folder when ``--out`` is not given: ``runs/<spec>-<date-time>`` (UTC)."""
    stem = Path(spec).name.split(".")[0]
    stamp = datetime.now(UTC).strftime("%Y%m%d-%H%M%S")
    return Path("runs") / f"{stem}-{stamp}"


def claim_default_out(out: Path) -> Path:
    """``out`` (the default folder, :func:`default_out`) created now, or when another run
    took it (two started in the same second, by a script) the first of ``out-2``,
    ``out-3``… that this call creates: runs started together each get their own folder.
    A folder that cannot be made is returned as it is, for the store to say why."""
    for n in range(1, 1000):
        candidate = out if n == 1 else out.with_name(f"{out.name}-{n}")
        try:
            candidate.mkdir(parents=True)
        except FileExistsError:
            continue
        except OSError:
            return candidate
        return candidate
    return out


def engine_settings(path: str | None) -> dict[str, Any]:
    """The settings of an ``--engine-config`` file as the plan stores them (``{}``: none)."""
    if path is None:
        return {}
    from opspec.commands._files import check_nesting
    from opspec.engine.config import EngineConfig

    check_nesting(path, "the engine configuration")
    return asdict(EngineConfig.load(path))


def new_plan(args: argparse.Namespace) -> tuple[Any, dict[str, Any]]:
    """The plan of a new run, and the front hall's decision on each design's spec and the
    user model (:func:`check_plan` reuses them: nothing is read and checked twice)."""
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
    # a spec that declares no metrics is measured per process (opspec.model.default_metrics)
    a = prepare(RunRequest(args.spec, days=args.days, user_model=args.user_model,
                           branches=branches or None, default_metrics=True))
    model = a.user_model
    decided = {str(args.spec): a}
    for _label, path in specs[1:]:
        b = prepare(RunRequest(path, days=args.days, user_model=model, no_user=model is None,
                               branches=branches or None, default_metrics=True))
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
    export = export_formats(args.export)
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
                          seed=run_seed, user_model=model, engine=engine_settings(args.engine_config),
                          export=export, case=args.case or "chain",
                          input_uncertainty=draws, users_per_draw=per_draw,
                          run_inputs=RunInputs(draws=inputs.draws, rows=inputs.rows,
                                               source=inputs.source).to_json()
                          if inputs.draws or inputs.rows else {}, branches=branches), decided


def check_plan(plan: Any, decided: dict[str, Any] | None = None
                ) -> dict[str, list[dict[str, Any]]]:
    """Load every design and the user model once, before any simulation: bad inputs stop the
    run here (``decided``: what :func:`new_plan` read and checked already, by spec).
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
        _say_default_metrics(design.spec, context.compiled.package.metrics, shown)
    if plan.input_uncertainty:          # the fitted model's draws: there, and enough of them
        from opspec.evaluation.input_uncertainty import check_draws

        check_draws(plan)
    return definitions


def _say_default_metrics(spec: str, metrics: Any, shown: set[str]) -> None:
    """Say, once, that a spec declaring no metrics is measured by opspec's defaults."""
    from opspec.model.default_metrics import is_default

    names = [m.name for m in metrics if is_default(m.description)]
    said = (f"opspec evaluate: {spec}: the spec declares no metrics (opspec:Metrics), so "
            f"each process is measured by default: {', '.join(names)} (docs/evaluation.md, "
            "Default metrics; declare your own to measure what matters)")
    if names and said not in shown:
        shown.add(said)
        print(said, file=sys.stderr)


def refuse_spec_template(args: argparse.Namespace) -> None:
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


def refuse_inputs_in_out(args: argparse.Namespace, plan: Any, out: Path) -> None:
    """No file the evaluation writes into ``out`` may be one it reads (exit 2, both
    named): a report template named ``OUT/report.html``, a spec in ``OUT/figures/``…"""
    from opspec.commands._files import refuse_overwrite, spec_inputs
    from opspec.evaluation.replication import prepare

    reads: list[Any] = []
    for design in plan.designs:
        what = "SPEC" if design.label == "A" else f"design {design.label}"
        reads.append((what, design.spec))
        # loaded once per process already (check_plan): the same context, from its cache
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
    refuse_overwrite(writes, reads, folders=[(f"--out {out}", out / "figures")])


def refuse_file_out(out: Path) -> None:
    """``--out`` names the folder the evaluation writes into: a file there (or a file
    where one of its parent folders would be) is refused before anything runs, saying so
    (exit 2; it was "cannot create the output folder: File exists")."""
    for where in (out, *out.parents):
        if where.exists() or where.is_symlink():
            if not where.is_dir():
                what = (f"--out {out} is a file" if where == out
                        else f"--out {out}: {where} is a file")
                raise EvaluationError(
                    f"{what}, not a folder: --out (-o) names the folder the evaluation "
                    "writes its results, report and figures into",
                    hint="give a new or an existing folder (--out runs/my-evaluation), or "
                    "leave --out out for runs/<spec>-<date-time>")
            return


def refuse_earlier_outputs(out: Path) -> None:
    """A new run does not go into a folder that holds what an earlier evaluation wrote
    (its results.sqlite gone): it would overwrite the report and leave that run's figures
    (a comparison's B-*), traces and SQLite write-ahead log beside its own results (exit 2,
    the files named)."""
    names = [*(name for name in OUT_FILES if name != "results.sqlite"), *EXPORT_FILES.values(),
             *(name + ".partial" for name in EXPORT_FILES.values())]
    found = [name for name in names if (out / name).exists()]
    with contextlib.suppress(OSError):
        if (out / "figures").is_dir() and any((out / "figures").iterdir()):
            found.append("figures/")
    if found:
        raise EvaluationError(
            f"--out {out} holds the outputs of an earlier evaluation ({', '.join(found)}) "
            "but no results.sqlite; a new run would overwrite some and leave the others "
            "beside its results",
            hint="choose another --out, or move those files away first")
