"""Check XPDL / SISARL-XPDL or BPMN 2.0 specifications and report every problem.

Load each PATH (a file, or a folder: every *.xpdl, *.xml and *.bpmn below it, sorted), run the
structural checks and report every problem at once as 'path:line: severity: message (hint)',
followed by a summary line; --json prints one JSON object per file instead (JSON Lines,
opspec.xpdl.validate.FileReport.to_json, plus the key of a problem in a TOML file and the
side files).
Codes are listed in docs/validation.md.

The files opspec run SPEC would read beside the spec are checked with it, as the run checks
them: the companion user model SPEC.users.toml (read, and checked against the spec's user lane)
and the world file the spec names (opspec:WorldFile). The summary names them ('1 file checked
with pill.users.toml beside it'); one that is absent is no problem. --user-model FILE|PRESET
checks that user model (or population) instead of the companion, as opspec run or evaluate
given it would read it ('1 file checked with pill.population.toml as its user model').

Exit status: 0 no errors; 1 errors in a spec or a file beside it; 2 usage or I/O (a path that
does not exist, an unreadable file, a folder without specs).
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from opspec.commands._args import add_json, add_strict, command

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    parser = command(subparsers, "validate", __doc__)
    parser.add_argument("paths", nargs="+", metavar="PATH", help="spec files or folders")
    add_strict(parser)
    add_json(parser, "one JSON object per file (JSON Lines)")
    parser.add_argument("--user-model", metavar="FILE|PRESET",
                        help="check this user model (or population) against each spec's "
                        "user lane, as opspec run / evaluate --user-model would read it, "
                        "instead of the companion SPEC.users.toml")
    parser.add_argument("--schema", action="store_true",
                        help="also validate each file against the bundled WfMC XSD of its "
                        "XPDL version (1.0, 2.1; docs/validation.md)")
    parser.set_defaults(handler=run)


def engine_checks(package: Any) -> list[Any]:
    """What only the engine and the bindings can judge: whether the engine compiles the
    package (``not-runnable``: anything ``run``, ``evaluate``, the walkthrough or ``compile``
    would refuse, at its line), the monitors the spec declares (``bad-monitor``) and whether
    its world can be built (``bad-world``). A package written for another script language
    (JaWE's ``Script Type="text/javascript"``) is told so in the hint."""
    import dataclasses

    from opspec.commands._spec import NOT_RUNNABLE, engine_diagnostics

    found = engine_diagnostics(package, world=True)
    if not any(d.code == NOT_RUNNABLE for d in found):
        found.extend(_zero_time_cycles(package))
    language = (getattr(package, "script_language", None) or "").strip()
    if language and any(word in language.lower() for word in _FOREIGN_SCRIPTS):
        note = (f"the package declares Script Type {language!r}: opspec evaluates its own "
                "expression grammar (data fields, arithmetic, comparisons, durations), not "
                f"{language} code")
        found = [dataclasses.replace(d, hint=f"{note}; {d.hint}" if d.hint else note)
                 if d.code == NOT_RUNNABLE else d for d in found]
    return found


def _zero_time_cycles(package: Any) -> list[Any]:
    """The cycles a run can stop in with its clock stopped (``zero-time-cycle``, as ``opspec
    check`` finds them: a warning, an error for workflows certain to start each other without
    end). Without them validate passed a spec whose run stops at t = 0, and only ``check``
    said why."""
    from opspec.engine.compiled import compile_package
    from opspec.engine.zero_time_check import KIND, zero_time_cycles
    from opspec.errors import Diagnostic, Severity, SourceLocation

    source = str(getattr(package, "source", None) or "<spec>")
    return [Diagnostic(SourceLocation(source, problem.line),
                       Severity.ERROR if problem.severity == "error" else Severity.WARNING,
                       KIND, f"{problem.process}: {problem.message}",
                       "give the cycle a duration, a wait, or a condition that lets the token "
                       "out; opspec check shows the way into it"
                       + (f" ({' -> '.join(problem.witness)})" if problem.witness else ""))
            for problem in zero_time_cycles(compile_package(package))]


# Script languages whose expressions opspec does not evaluate (the package's Script Type).
_FOREIGN_SCRIPTS = ("javascript", "java", "python", "groovy", "mvel", "ecmascript")


def run(args: argparse.Namespace) -> int:
    from opspec.commands._spec import where_to_look
    from opspec.xpdl.validate import spec_files, summary

    files, problems = spec_files(args.paths, where_to_look=where_to_look)
    for problem in problems:
        print(f"opspec validate: {problem}", file=sys.stderr)
    reports = []
    beside: dict[str, bool] = {}          # name: checked (not only read)
    given: dict[str, bool] = {}           # the same, of --user-model
    for path in files:
        report, side = _with_side_files(path, strict=args.strict, user_model=args.user_model)
        if args.schema:
            from opspec.xpdl.schema import add_schema

            report = add_schema(report, path, strict=args.strict)
        reports.append(report)
        for side_file in side:
            names = given if side_file.given else beside
            names[side_file.path.name] = names.get(side_file.path.name, True) and (
                side_file.checked)
        if args.json:
            doc = report.to_json()
            # a problem in a TOML file (a side file) is placed by its key, which only the
            # text line showed: activities.walk.duration
            doc["diagnostics"] = [{**d.to_json(), **({"key": d.location.key}
                                                     if d.location.key else {})}
                                  for d in report.diagnostics]
            doc["side_files"] = [f.to_json() for f in side]
            print(json.dumps(doc, ensure_ascii=False))
        else:
            for line in report.lines():
                print(line)
    if not args.json and reports:
        print(summary(reports, beside=[name for name, checked in beside.items() if checked],
                      only_read=[name for name, checked in beside.items() if not checked],
                      given=[name for name, checked in given.items() if checked],
                      given_only_read=[name for name, checked in given.items()
                                       if not checked]))
    if problems or any(r.unreadable for r in reports):
        return 2
    return 0 if all(r.ok for r in reports) else 1


def _with_side_files(path: Any, *, strict: bool, user_model: str | None = None
                     ) -> tuple[Any, list[Any]]:
    """The report on the spec at ``path`` with the problems of the files a run of it reads
    beside it (:mod:`opspec.commands.validate_side_files`), and those files."""
    import dataclasses

    from opspec.commands.validate_side_files import check_side_files
    from opspec.errors import Severity
    from opspec.xpdl.validate import FileReport, merge_diagnostics, validate_spec

    package, report = validate_spec(path, extra=engine_checks)
    found, side = check_side_files(path, package, report.diagnostics, user_model)
    diagnostics = merge_diagnostics(report.diagnostics, found) if found else report.diagnostics
    if strict:          # every warning an error, the side files' too
        diagnostics = tuple(dataclasses.replace(d, severity=Severity.ERROR)
                            if d.severity is Severity.WARNING else d for d in diagnostics)
    return FileReport(report.path, report.version, diagnostics), side
