"""``opspec fit TRACE... -o model.toml``: estimate a user model from recorded traces."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "fit", help="estimate a user model from recorded traces",
        description="Read JSON Lines traces (opspec run --trace, opspec evaluate --export "
        "jsonl, TUI walkthroughs), estimate per manual activity a duration distribution "
        "(lognormal, gamma, Weibull or ex-Gaussian by maximum likelihood, chosen by AIC or "
        "BIC; the comparison is printed), omission rates with Wilson intervals, choice "
        "probabilities with the time a wrong pick costs, and how much users (runs) differ; "
        "write a user-model TOML file (docs/fitting.md).")
    parser.add_argument("traces", nargs="+", metavar="TRACE",
                        help="trace files (.jsonl), or folders holding them")
    parser.add_argument("-o", "--output", required=True, metavar="MODEL.toml",
                        help="where to write the fitted model ('-' for standard output)")
    parser.add_argument("--lane", default="user",
                        help="lane or participant whose activities are fitted (default: user)")
    parser.add_argument("--name", help="model name (default: the output file's stem)")
    parser.add_argument("--criterion", choices=("aic", "bic"), default="aic",
                        help="how the duration family is chosen (default: aic)")
    parser.add_argument("--min-per-user", type=int, default=10, metavar="N",
                        help="observations a user (run) needs to count in the between-user "
                        "spread (default: 10)")
    parser.add_argument("--json", action="store_true",
                        help="print the fit (every family's AIC/BIC, intervals, between-user "
                        "spread) as one JSON object instead of the summary")
    parser.set_defaults(handler=_fit)


def _vary_text(vary: dict[str, Any]) -> str:
    """The ``[vary.activities.ID.PART.PARAM]`` tables of the between-user variation."""
    import tomli_w

    if not vary:
        return ""
    return ("\n# ---- between users: parameters drawn once per simulated user (estimated per "
            "user, then pooled;\n# docs/fitting.md)\n"
            + tomli_w.dumps({"vary": {"activities": vary}}))


def _fit(args: argparse.Namespace) -> int:
    from opspec.errors import UserModelError
    from opspec.usermodels.fitting import fit_traces, iter_paths
    from opspec.usermodels.loader import dump_user_model, load_user_model

    if args.min_per_user < 2:
        raise UserModelError(f"--min-per-user must be at least 2, not {args.min_per_user}",
                             hint="a user's own estimate needs two observations or more")
    if args.json and args.output == "-":
        raise UserModelError("--json and -o - both want standard output",
                             hint="write the model to a file with -o FILE")
    paths = iter_paths(args.traces)
    if not paths:
        raise UserModelError("no trace files found in " + ", ".join(args.traces),
                             hint="give .jsonl trace files or folders holding them")
    out = Path(args.output) if args.output != "-" else None
    name = args.name or (out.stem.removesuffix(".users") if out else "fitted")
    result = fit_traces(paths, lane=args.lane, name=name, criterion=args.criterion,
                        min_per_user=args.min_per_user)
    by = args.criterion.upper()
    header = (f"User model fitted by `opspec fit` from {len(paths)} trace file(s) "
              f"({result.observations.events} events, {result.observations.runs} run(s), "
              f"lane {args.lane!r}).\n"
              "Durations: lognormal, gamma, Weibull and ex-Gaussian were fitted to each activity "
              f"by maximum\nlikelihood; the one with the lowest {by} is used, as the table above "
              "each activity shows.\nOmission rates carry Wilson 95 % intervals. Between-user "
              "spread (users = runs with at least\n"
              f"{args.min_per_user} observations) is in the comments and `opspec fit --json`; "
              "where the data show\nthat users differ, [vary] tables at the end draw those "
              "parameters per simulated user.\nCheck the numbers before relying on them: "
              "small samples give wide intervals.")
    text = dump_user_model(result.model, comments=result.comments(), header=header)
    text += _vary_text(result.vary())
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
    if args.json:
        doc = {"model": str(out), "lane": args.lane, "criterion": args.criterion,
               "min_per_user": args.min_per_user, **result.to_json()}
        print(json.dumps(doc, indent=1, default=str))
        return 0
    for fit in result.fits:
        print(fit.comment())
        print()
    activities = ", ".join(f.activity for f in result.fits)
    print(f"wrote {out} ({len(result.fits)} activities: {activities})")
    return 0
