"""``opspec check SPEC...``: soundness of each process's control flow (docs/soundness.md).

Exit status: 0 every process is sound; 1 a problem was found (or a spec has errors); 2 usage,
I/O, or a state space too large to decide within ``--max-states``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "check", help="check the soundness of each process (deadlocks, livelocks, dead "
        "activities, improper completion, graph conformance)",
        description="Explore each process's control flow with data abstracted (every "
        "conditional branch may be taken) and report deadlocks, livelocks, activities that "
        "can never run, improper completion, AND-joins that can't fire and unbounded places, "
        "each with a witness path; plus violations of the package's declared graph "
        "conformance class. Exit status: 0 sound, 1 a problem found, 2 usage or I/O errors "
        "or a state space larger than --max-states.")
    parser.add_argument("specs", nargs="+", metavar="SPEC", help="spec files or folders")
    parser.add_argument("--json", action="store_true", help="one JSON object per file")
    parser.add_argument("--max-states", type=int, default=100_000, metavar="N",
                        help="markings explored per process level (default 100000)")
    parser.add_argument("--process", metavar="ID", help="check only this process")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from opspec.model.soundness import check_process
    from opspec.xpdl.loader import load_package
    from opspec.xpdl.validate import spec_files

    files, usage = spec_files(args.specs)
    for message in usage:
        print(f"opspec check: {message}")
    worst = 2 if usage else 0
    for path in files:
        result = load_package(path)
        if result.package is None or not result.ok:
            for diagnostic in result.errors or result.diagnostics:
                print(diagnostic)
            worst = max(worst, 1)
            continue
        package = result.package
        reports = []
        for process in package.processes:
            if args.process and process.id != args.process:
                continue
            reports.extend(check_process(process, conformance=package.conformance_class,
                                         max_states=args.max_states))
        status = _print(path, reports, as_json=args.json, max_states=args.max_states)
        worst = max(worst, status)
    return worst


def _print(path: Path, reports: list[Any], *, as_json: bool, max_states: int) -> int:
    problems = [p for r in reports for p in r.problems]
    undecided = [r for r in reports if not r.complete]
    if as_json:
        print(json.dumps({
            "path": str(path), "sound": not problems and not undecided,
            "processes": [{"process": r.process, "states": r.states, "complete": r.complete,
                           "sound": r.sound} for r in reports],
            "problems": [{"kind": p.kind, "process": p.process, "activity": p.activity,
                          "line": p.line, "message": p.message, "witness": list(p.witness)}
                         for p in problems]}))
    else:
        for problem in problems:
            where = f"{path}:{problem.line}" if problem.line else str(path)
            print(f"{where}: error: {problem.process}: {problem.message}")
            if problem.witness:
                print(f"    witness: {' -> '.join(problem.witness)}")
        for report in undecided:
            print(f"{path}: {report.process}: more than {max_states} states: soundness "
                  "undecided (raise --max-states, or simplify the process)")
        sound = sum(1 for r in reports if r.sound)
        print(f"{path}: {sound} of {len(reports)} process level(s) sound, "
              f"{len(problems)} problem(s)")
    if problems:
        return 1
    return 2 if undecided else 0
