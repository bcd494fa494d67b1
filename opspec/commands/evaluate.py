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
import os
import sys
from typing import Any

from opspec.commands import _args
from opspec.commands.evaluate_exports import EXPORT_FILES, EXPORTS
from opspec.commands.evaluate_plan import DEFAULT_SEED, DEFAULT_USERS, OUT_FILES
from opspec.errors import EvaluationError

# This module holds the command's options and its start; the rest is one concern a module,
# each importing what is heavy only when used (building the parser stays light): the plan
# and its checks (evaluate_plan), the exports (evaluate_exports), a stored run and its
# resumption (evaluate_resume), the run (evaluate_run) and what it prints (evaluate_output).
# The constants that moved stay importable from here.
__all__ = ["DEFAULT_SEED", "DEFAULT_USERS", "EXPORTS", "EXPORT_FILES", "OUT_FILES", "register",
           "run"]


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
                        help="worker processes (default, and at most: the cores this "
                        "process may run on)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on an existing Dask distributed cluster (tcp://host:8786)")
    parser.add_argument("--scheduler-timeout", type=float, default=None, metavar="SECONDS",
                        help="with --scheduler: how long to wait for the cluster to have a "
                        "worker, at the start and whenever all have left (default 60)")
    parser.add_argument("-o", "--out", metavar="DIR",
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
    # `--report DIR` (model-check's option) would be taken for --report-template, its value
    # read as a template: said here what writes the report instead
    parser.add_argument("--report", nargs="?", action=_NoReportOption, help=argparse.SUPPRESS)
    parser.set_defaults(handler=run)


class _NoReportOption(argparse.Action):
    """``--report``, which evaluate does not take: every evaluation writes its report."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: Any, option_string: str | None = None) -> None:
        message = ("--report is not an option of evaluate: every evaluation writes its "
                   "report, OUT/report.html with report.md and figures/ beside it; choose "
                   "OUT with --out DIR (--report-template FILE: a template of your own for "
                   "report.html)")
        parser._bad_value = message        # type: ignore[attr-defined]  # one line (Parser)
        parser.error(message)


def _local_cores() -> int:
    """The cores this process may run on (a container or taskset may allow fewer than the
    machine has)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def run(args: argparse.Namespace) -> int:
    cores = _local_cores()
    workers = args.workers if args.workers is not None else cores
    if workers < 1:
        raise EvaluationError(f"--workers must be >= 1, not {workers}")
    listing = bool(args.sweep) and args.sweep[0] == "list"
    if workers > cores and not args.scheduler and not listing:
        # the results are the same for any number of workers (docs/evaluation.md): a
        # process more than the cores runs no sooner, it only takes memory and start-up
        print(f"opspec evaluate: --workers {workers}: this process may run on {cores} "
              f"core{'s' * (cores != 1)}, so {cores} worker{'s run' if cores != 1 else ' runs'} (the "
              "results are the same for any number of workers)", file=sys.stderr)
        workers = cores
    from opspec.evaluation import plots

    # the report's drawing processes (--workers W > 1) start now: the first imports
    # matplotlib while this process loads and checks the specs and the user model (the
    # run's one serial part, which leaves the other cores idle), then forks the others,
    # which inherit its import; a bad input ends them at once (plots.drawing_processes), so
    # its error comes as fast as before
    with plots.drawing_processes(1 if listing else min(workers, cores)):
        from opspec.commands.evaluate_run import evaluate

        return evaluate(args, workers, cores)
