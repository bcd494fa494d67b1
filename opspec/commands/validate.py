"""Check XPDL / SISARL-XPDL or BPMN 2.0 specifications and report every problem.

Load each PATH (a file, or a folder: every *.xpdl, *.xml and *.bpmn below it, sorted), run the
structural checks and report every problem at once as 'path:line: severity: message (hint)',
followed by a summary line; --json prints one JSON object per file instead (JSON Lines,
opspec.xpdl.validate.FileReport.to_json). Codes are listed in docs/validation.md.

Exit status: 0 no errors; 1 errors in a spec; 2 usage or I/O (a path that does not exist, an
unreadable file, a folder without specs).
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
    language = (getattr(package, "script_language", None) or "").strip()
    if language and any(word in language.lower() for word in _FOREIGN_SCRIPTS):
        note = (f"the package declares Script Type {language!r}: opspec evaluates its own "
                "expression grammar (data fields, arithmetic, comparisons, durations), not "
                f"{language} code")
        found = [dataclasses.replace(d, hint=f"{note}; {d.hint}" if d.hint else note)
                 if d.code == NOT_RUNNABLE else d for d in found]
    return found


# Script languages whose expressions opspec does not evaluate (the package's Script Type).
_FOREIGN_SCRIPTS = ("javascript", "java", "python", "groovy", "mvel", "ecmascript")


def run(args: argparse.Namespace) -> int:
    from opspec.xpdl.validate import spec_files, summary, validate_file

    files, problems = spec_files(args.paths)
    for problem in problems:
        print(f"opspec validate: {problem}", file=sys.stderr)
    reports = []
    for path in files:
        report = validate_file(path, strict=args.strict, extra=engine_checks)
        if args.schema:
            from opspec.xpdl.schema import add_schema

            report = add_schema(report, path, strict=args.strict)
        reports.append(report)
        if args.json:
            print(json.dumps(report.to_json(), ensure_ascii=False))
        else:
            for line in report.lines():
                print(line)
    if not args.json and reports:
        print(summary(reports))
    if problems or any(r.unreadable for r in reports):
        return 2
    return 0 if all(r.ok for r in reports) else 1
