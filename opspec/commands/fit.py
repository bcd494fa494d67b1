"""Estimate a user model from recorded traces.

Read JSON Lines traces (opspec run --trace, opspec evaluate --export jsonl, TUI walkthroughs),
estimate per manual activity a duration distribution (lognormal, gamma, Weibull or
ex-Gaussian by maximum likelihood, chosen by AIC or BIC; the comparison is printed), omission
rates with Wilson intervals, choice probabilities with the time a wrong pick costs, and how
much users (runs) differ; write a user-model TOML file (docs/fitting.md).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.commands import _args
from opspec.commands.model_check import add_person_options

if TYPE_CHECKING:
    from opspec.usermodels.uncertainty import ParameterDraws

__all__ = ["fitted_text", "register"]


def register(subparsers: Any) -> None:
    parser = _args.command(subparsers, "fit", __doc__)
    parser.add_argument("traces", nargs="+", metavar="TRACE",
                        help="trace files (.jsonl), or folders holding them")
    parser.add_argument("-o", "--output", required=True, metavar="MODEL.toml",
                        help="where to write the fitted model ('-' for standard output)")
    _args.add_lane(parser, "fitted")
    parser.add_argument("--name", help="model name (default: the output file's stem)")
    parser.add_argument("--criterion", choices=("aic", "bic"), default="aic",
                        help="how the duration family is chosen (default: aic)")
    parser.add_argument("--min-per-user", type=int, default=10, metavar="N",
                        help="observations a person needs to count in the between-user "
                        "spread (default: 10)")
    add_person_options(parser, "in the between-user spread and in the bootstrap of --draws")
    parser.add_argument("--draws", type=int, default=200, metavar="B",
                        help="bootstrap redraws of the fitted parameters written to the "
                        "model's [uncertainty] table, for `opspec evaluate "
                        "--input-uncertainty` (default: 200; 0: none)")
    _args.add_seed(parser, what="seed of the bootstrap redraws")
    _args.add_json(parser, "the fit (every family's AIC/BIC, intervals, between-user "
                   "spread) as one JSON object instead of the summary")
    cv = parser.add_argument_group(
        "cross-validation", "--holdout K: split the persons into K folds; for each, fit "
        "on the others and check the model on the fold (opspec model-check); one verdict "
        "over all folds, Holm-adjusted; exit 1 when something misfits (docs/fitting.md)")
    cv.add_argument("--holdout", type=int, metavar="K",
                    help="K-fold cross-validation by person")
    _args.add_check_options(cv, level_of="the verdict")
    parser.set_defaults(handler=_fit)


def _vary_text(vary: dict[str, Any]) -> str:
    """The ``[vary.activities.ID.PART.PARAM]`` tables of the between-user variation."""
    import tomli_w

    if not vary:
        return ""
    return ("\n# ---- between users: parameters drawn once per simulated user (estimated per "
            "user, then pooled;\n# docs/fitting.md)\n"
            + tomli_w.dumps({"vary": {"activities": vary}}))


def _sessions_per_person(obs: Any) -> dict[str, int]:
    counts: dict[str, int] = {}
    for person in obs.person_of.values():
        counts[person] = counts.get(person, 0) + 1
    return counts


def _persons_line(obs: Any, source: str) -> str:
    """``3 persons, 7 sessions (P01 3, P02 2, P03 2)``: who the sessions were."""
    counts = _sessions_per_person(obs)
    shown = ", ".join(f"{p} {n}" for p, n in list(counts.items())[:8])
    more = f", ... {len(counts) - 8} more" if len(counts) > 8 else ""
    how = {"auto": "", "run": "; each run a person"}.get(source, f"; by {source}")
    return (f"{len(counts)} person(s), {obs.sessions} session(s)"
            + (f" ({shown}{more})" if any(n > 1 for n in counts.values()) else "") + how)


def _specs(paths: list[Path]) -> dict[str, int]:
    """How many of the traces each spec named in their headers was recorded with."""
    from opspec.usermodels.trace_reader import trace_header

    files: dict[str, int] = {}
    for path in paths:
        spec = trace_header(path).get("spec")
        if isinstance(spec, str) and spec:
            files[Path(spec).name] = files.get(Path(spec).name, 0) + 1
    return dict(sorted(files.items()))


def _specs_line(files: dict[str, int]) -> str | None:
    """A line when the traces were recorded with more than one spec (a study's variants, a
    trace of another device): one model is fitted over all of them, which is said."""
    if len(files) < 2:
        return None
    shown = "; ".join(f"{name}: {n} file(s)" for name, n in files.items())
    return (f"specs: the traces were recorded with {len(files)} specs ({shown}): one model "
            "is fitted over all of them; fit each spec's traces on their own for a model of "
            "each")


def _uncertainty_text(draws: ParameterDraws | None) -> str:
    """The ``[uncertainty]`` table: the bootstrap redraws of the fitted parameters."""
    if draws is None:
        return ""
    return ("\n# ---- parameter uncertainty: each draw is the model refitted to a bootstrap "
            "resample of the\n# traces; `opspec evaluate --input-uncertainty B` runs draws "
            "1..B (docs/fitting.md)\n" + draws.to_text())


def fitted_text(result: Any, draws: ParameterDraws | None, header: str = "") -> str:
    """The model file ``opspec fit`` writes for ``result``: the model with its comments, the
    ``[vary]`` tables, whom it was fitted on (``[fitted_on]``) and the ``[uncertainty]``
    redraws."""
    from opspec.usermodels.fitted_on import fitted_on_text
    from opspec.usermodels.loader import dump_user_model

    text = dump_user_model(result.model, comments=result.comments(), header=header)
    return (text + _vary_text(result.vary()) + fitted_on_text(result.observations.persons)
            + _uncertainty_text(draws))


def _fit(args: argparse.Namespace) -> int:
    from opspec.errors import UserModelError
    from opspec.usermodels.fitting import fit_traces
    from opspec.usermodels.loader import load_user_model

    if args.min_per_user < 2:
        raise UserModelError(f"--min-per-user must be at least 2, not {args.min_per_user}",
                             hint="a user's own estimate needs two observations or more")
    if args.json and args.output == "-":
        raise UserModelError("--json and -o - both want standard output",
                             hint="write the model to a file with -o FILE")
    if args.holdout is not None and args.output == "-":
        raise UserModelError("--holdout and -o - both want standard output (the folds' "
                             "checks are printed after the model is written)",
                             hint="write the model to a file with -o FILE")
    if args.draws < 0:
        raise UserModelError(f"--draws must be 0 or more, not {args.draws}")
    from opspec.usermodels.persons import PersonRule, parse_person_options

    persons = PersonRule(args.person_from, args.person_pattern,
                         parse_person_options(args.person))
    if args.holdout is not None:        # refuse bad options before the first fit
        from opspec.commands.model_check import CheckOptions, check_options

        check_options(CheckOptions(level=args.level, replicates=args.replicates,
                                   runs=args.runs))
    from opspec.commands.model_check import trace_files

    paths = trace_files(args.traces, "fit")
    out = Path(args.output) if args.output != "-" else None
    from opspec.commands._files import refuse_overwrite

    refuse_overwrite([("-o", out)], [("a TRACE", path) for path in paths])
    if out is not None:
        from opspec.commands._files import unwritable

        problem = unwritable(out)
        if problem is not None:     # said now, not after the fitting and its bootstrap
            raise UserModelError(problem, hint="choose a writable path with -o")
    name = args.name or (out.stem.removesuffix(".users") if out else "fitted")
    result = fit_traces(paths, lane=args.lane, name=name, criterion=args.criterion,
                        min_per_user=args.min_per_user, persons=persons)
    obs = result.observations
    if args.holdout is not None:        # folds that cannot be made: said before writing
        from opspec.commands.model_check import fold_persons

        fold_persons(paths, obs, args.holdout)
    from opspec.usermodels.bootstrap import parameter_draws

    draws = parameter_draws(result, args.draws, seed=args.seed) if args.draws else None
    by = args.criterion.upper()
    header = (f"User model fitted by `opspec fit` from {len(paths)} trace file(s) "
              f"({obs.events} events, {obs.sessions} session(s) of {len(obs.persons)} "
              f"person(s), lane {args.lane!r}).\n"
              f"Persons: {_persons_line(obs, args.person_from)}.\n"
              "Durations: lognormal, gamma, Weibull and ex-Gaussian were fitted to each activity "
              f"by maximum\nlikelihood; the one with the lowest {by} is used, as the table above "
              "each activity shows.\nOmission rates carry Wilson 95 % intervals. Between-user "
              "spread (persons with at least\n"
              f"{args.min_per_user} observations) is in the comments and `opspec fit --json`; "
              "where the data show\nthat users differ, [vary] tables at the end draw those "
              "parameters per simulated user.\nCheck the numbers before relying on them: "
              "small samples give wide intervals.")
    text = fitted_text(result, draws, header)
    if out is None:
        sys.stdout.write(text)
        return 0
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text, encoding="utf-8")
    except OSError as error:
        raise UserModelError(f"cannot write the model: {error.strerror or error}",
                             hint="choose a writable path with -o") from None
    load_user_model(out)  # the file must read back; a failure here is a bug worth reporting
    holdout = _holdout(args, paths, persons) if args.holdout is not None else None
    status = 0 if holdout is None or holdout.fits else 1
    if args.json:
        doc = {"model": str(out), "lane": args.lane, "criterion": args.criterion,
               "min_per_user": args.min_per_user, **result.to_json(),
               "persons": {"count": len(obs.persons), "sessions": obs.sessions,
                           "from": args.person_from,
                           "sessions_per_person": _sessions_per_person(obs)},
               "uncertainty": None if draws is None else {
                   "draws": draws.count, "resampled": draws.resampled, "seed": draws.seed,
                   "parameters": draws.summary()},
               "unusable_durations": dict(sorted(obs.unusable.items())),
               "specs": _specs(paths),
               "left_out_without_lane": [{"file": path, "lanes_seen": lanes}
                                         for path, lanes in obs.without_lane],
               "holdout": None if holdout is None else holdout.to_json()}
        print(json.dumps(doc, indent=1, default=str))
        return status
    for fit in result.fits:
        print(fit.comment())
        print()
    activities = ", ".join(f.activity for f in result.fits)
    print(f"persons: {_persons_line(obs, args.person_from)}")
    specs = _specs_line(_specs(paths))
    if specs is not None:
        print(specs)
    if draws is not None:
        print(f"parameter uncertainty: {draws.count} bootstrap redraws resampling "
              f"{draws.resampled} ([uncertainty]; opspec evaluate --input-uncertainty B)")
    print(f"wrote {out} ({len(result.fits)} activities: {activities})")
    if obs.unusable:    # walkthrough answers whose clock was paused, fast or skipped
        left = ", ".join(f"{activity} {n}" for activity, n in sorted(obs.unusable.items()))
        fitted = {f.activity for f in result.fits}
        missing = sorted(a for a in obs.unusable if a not in fitted)
        print(f"left out: {sum(obs.unusable.values())} walkthrough duration(s) not timed in "
              f"real time ({left}); their choices still count"
              + (f"; not in the model, none of their answers timed: {', '.join(missing)} "
                 "(record sessions in real time: docs/walkthrough.md)" if missing else ""))
    from opspec.usermodels.observations import without_lane_text

    without = without_lane_text(obs, args.lane)
    if without is not None:
        print(without)
    if holdout is not None:
        print()
        for line in holdout.lines():
            print(line)
    return status


def _holdout(args: argparse.Namespace, paths: list[Path], persons: Any) -> Any:
    """``--holdout K``: each fold fitted as this command fits (same options), then checked."""
    import tempfile

    from opspec.commands.model_check import CheckOptions, cross_validate
    from opspec.usermodels.bootstrap import parameter_draws
    from opspec.usermodels.fitting import fit_traces

    def fit(train: list[Path], model_path: Path, who: Any) -> None:
        result = fit_traces(train, lane=args.lane, name=model_path.stem,
                            criterion=args.criterion, min_per_user=args.min_per_user,
                            persons=who)
        draws = parameter_draws(result, args.draws, seed=args.seed) if args.draws else None
        model_path.write_text(fitted_text(result, draws), encoding="utf-8")

    options = CheckOptions(level=args.level, replicates=args.replicates, seed=args.seed,
                           lane=args.lane, spec=args.spec, days=args.days, runs=args.runs)
    with tempfile.TemporaryDirectory(prefix="opspec-holdout-") as work:
        return cross_validate(paths, persons, args.holdout, fit=fit, options=options,
                              work=Path(work))
