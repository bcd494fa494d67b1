"""``opspec preprocess IN [-o OUT.xpdl]``: SISARL-XPDL -> standard XPDL 2.1.

Coordination built-ins become compound built-in activities (BlockActivity + generated
ActivitySet of Routes and plain activities) and directives become ``opspec:`` extended
attributes; the output validates against the official XPDL 2.1 schema (docs/sisarl-xpdl.md,
section *Preprocessing*).

Exit status: 0 written, 1 the spec has errors (those ``opspec validate`` reports, or a
built-in that cannot be expanded; nothing written), 2 the input cannot be read or the output
cannot be written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "preprocess", help="translate SISARL-XPDL built-ins and directives into standard XPDL 2.1",
        description="Load IN, expand each coordination built-in (arbiter, voter, "
        "superposition, push/pull data, mode change) into a compound built-in activity and "
        "write standard XPDL 2.1 to OUT.")
    parser.add_argument("input", metavar="IN", help="the SISARL-XPDL specification")
    parser.add_argument("-o", "--output", metavar="OUT.xpdl",
                        help="where to write (default: IN with '.std.xpdl'; '-' for stdout)")
    parser.add_argument("--strict", action="store_true", help="treat warnings as errors")
    parser.set_defaults(handler=run)


def default_output(source: Path) -> Path:
    return source.with_name(f"{source.stem}.std.xpdl")


def run(args: argparse.Namespace) -> int:
    from opspec.commands.validate import engine_checks
    from opspec.errors import Severity
    from opspec.model.codec import write_atomically
    from opspec.xpdl.preprocess import preprocess
    from opspec.xpdl.schema_limits import schema_warnings
    from opspec.xpdl.validate import validate_spec
    from opspec.xpdl.writer import write_xpdl

    source = Path(args.input)
    if not source.is_file():
        what = "is a folder" if source.is_dir() else "does not exist"
        print(f"opspec preprocess: cannot read {source}: it {what}", file=sys.stderr)
        return 2
    # The spec is refused for exactly the errors `opspec validate` reports.
    package, report = validate_spec(source, strict=args.strict, extra=engine_checks)
    diagnostics = list(report.diagnostics)
    if report.ok and package is not None:
        result = preprocess(package)
        diagnostics.extend(result.diagnostics)
        package = result.package
        # The output promises standard XPDL 2.1: say when the schema would still reject it.
        diagnostics.extend(schema_warnings(package))
    for diagnostic in diagnostics:
        print(diagnostic, file=sys.stderr)
    errors = [d for d in diagnostics if d.severity is Severity.ERROR
              or (args.strict and d.severity is Severity.WARNING)]
    if package is None or errors:
        print(f"opspec preprocess: {source} has errors; nothing written", file=sys.stderr)
        return 1
    data = write_xpdl(package)
    if args.output == "-":
        sys.stdout.buffer.write(data)
        return 0
    target = Path(args.output) if args.output else default_output(source)
    try:
        write_atomically(target, data)
    except OSError as error:
        print(f"opspec preprocess: cannot write {target}: {error.strerror or error}",
              file=sys.stderr)
        return 2
    print(f"{target}: standard XPDL 2.1 from {source}")
    return 0

