"""``opspec fit TRACE... -o model.toml``: estimate a user model from recorded traces."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "fit", help="estimate a user model from recorded traces",
        description="Read JSON Lines traces (opspec run --trace, opspec evaluate --export "
        "jsonl, TUI walkthroughs), estimate per manual activity a duration distribution "
        "(lognormal or ex-Gaussian, chosen by AIC), omission rates with Wilson intervals and "
        "choice probabilities, and write a user-model TOML file (docs/user-models.md).")
    parser.add_argument("traces", nargs="+", metavar="TRACE",
                        help="trace files (.jsonl), or folders holding them")
    parser.add_argument("-o", "--output", required=True, metavar="MODEL.toml",
                        help="where to write the fitted model ('-' for standard output)")
    parser.add_argument("--lane", default="user",
                        help="lane or participant whose activities are fitted (default: user)")
    parser.add_argument("--name", help="model name (default: the output file's stem)")
    parser.set_defaults(handler=_fit)


def _fit(args: argparse.Namespace) -> int:
    from opspec.errors import UserModelError
    from opspec.usermodels.fitting import fit_traces, iter_paths
    from opspec.usermodels.loader import dump_user_model, load_user_model

    paths = iter_paths(args.traces)
    if not paths:
        raise UserModelError("no trace files found in " + ", ".join(args.traces),
                             hint="give .jsonl trace files or folders holding them")
    out = Path(args.output) if args.output != "-" else None
    name = args.name or (out.stem.removesuffix(".users") if out else "fitted")
    result = fit_traces(paths, lane=args.lane, name=name)
    header = (f"User model fitted by `opspec fit` from {len(paths)} trace file(s) "
              f"({result.observations.events} events, lane {args.lane!r}).\n"
              "Durations: lognormal (MLE) and ex-Gaussian (MLE) were fitted to each activity; "
              "the one with\nthe lower AIC is used, as the comment above each activity says. "
              "Omission rates carry\nWilson 95 % intervals. Check the numbers before relying "
              "on them: small samples give wide intervals.")
    text = dump_user_model(result.model, comments=result.comments(), header=header)
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
    activities = ", ".join(f.activity for f in result.fits)
    print(f"wrote {out} ({len(result.fits)} activities: {activities})")
    return 0
