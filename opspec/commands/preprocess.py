"""Translate SISARL-XPDL built-ins and directives into standard XPDL 2.1.

Load IN, expand each coordination built-in (arbiter, voter, superposition, push/pull data,
mode change) into a compound built-in activity (BlockActivity + generated ActivitySet of
Routes and plain activities), turn directives into opspec: extended attributes, and write
standard XPDL 2.1 to OUT, valid against the official XPDL 2.1 schema (docs/sisarl-xpdl.md,
Preprocessing).

Relative companion paths follow the output: opspec:WorldFile, mode sources and
ExternalPackage hrefs are rewritten to lead from OUT's folder, and IN.users.toml is copied to
OUT.users.toml (opspec.xpdl.relocate). A world file that would then lie outside OUT's folder
tree (where opspec does not read it) is copied beside OUT instead. Every output the bundled
XPDL 2.1 XSD rejects gets a not-schema-valid warning.

Exit status: 0 written; 1 the spec has errors (those opspec validate reports, or a built-in
that cannot be expanded; nothing written); 2 the input cannot be read (missing, a folder, a
pipe or device, no permission) or is a compiled workflow script (.wfs), the output is a file
the spec reads (itself, its user model, its world file, a mode's spec), or the output cannot
be written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from opspec.commands._args import add_translation, command

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = command(subparsers, "preprocess", __doc__)
    add_translation(parser, "SISARL-XPDL", "OUT.xpdl", "IN with '.std.xpdl'; '-' for stdout")
    parser.set_defaults(handler=run)


def default_output(source: Path) -> Path:
    return source.with_name(f"{source.stem}.std.xpdl")


def run(args: argparse.Namespace) -> int:
    from opspec.commands._companions import copy_companion, copy_user_model
    from opspec.commands._files import (
        overwrite_problem,
        spec_inputs,
        translation_problem,
        write_problem,
    )
    from opspec.commands.validate import engine_checks
    from opspec.errors import Severity
    from opspec.model.codec import write_atomically
    from opspec.xpdl.open_spec import IO_CODES
    from opspec.xpdl.preprocess import preprocess
    from opspec.xpdl.relocate import relocate
    from opspec.xpdl.schema import output_schema_warnings
    from opspec.xpdl.validate import validate_spec
    from opspec.xpdl.writer import write_xpdl

    source = Path(args.input)
    target = None if args.output == "-" else (
        Path(args.output) if args.output else default_output(source))
    problem = translation_problem("preprocess", source, target,
                                  example=default_output(source).name)
    if problem is not None:
        print(problem, file=sys.stderr)
        return 2
    # The spec is refused for exactly the errors `opspec validate` reports.
    package, report = validate_spec(source, strict=args.strict, extra=engine_checks)
    diagnostics = list(report.diagnostics)
    if any(d.code == "compiled-script" for d in diagnostics):
        # the wrong file (a script has no SISARL built-ins left), not a spec with errors
        print(f"opspec preprocess: {source} is a compiled workflow script (.wfs), not XPDL; "
              "nothing written. Preprocess the XPDL it was compiled from", file=sys.stderr)
        return 2
    if any(d.code in IO_CODES for d in diagnostics):
        for diagnostic in diagnostics:
            print(diagnostic, file=sys.stderr)
        print(f"opspec preprocess: cannot read {source}; nothing written", file=sys.stderr)
        return 2
    if target is not None and package is not None:
        # -o naming a file the spec reads (its world file, a mode's spec) would replace it
        problem = overwrite_problem("preprocess", [("-o", target)],
                                    spec_inputs(source, package),
                                    example=default_output(source).name)
        if problem is not None:
            print(problem, file=sys.stderr)
            return 2
    copies: list[tuple[Path, Path]] = []          # world files to copy beside the output
    if report.ok and package is not None:
        result = preprocess(package)
        diagnostics.extend(result.diagnostics)
        package = result.package
        if target is not None:
            # Relative companion paths (world file, mode sources, external packages) lead
            # from the output's folder to the same files.
            package, moved = relocate(package, source, target, copies=copies)
            diagnostics.extend(moved)
        # The output promises standard XPDL 2.1: say when the schema would still reject it
        # (the known rules in words, anything else the bundled XSD finds as it says it).
        diagnostics.extend(output_schema_warnings(package, write_xpdl(package)))
    for diagnostic in diagnostics:
        print(diagnostic, file=sys.stderr)
    errors = [d for d in diagnostics if d.severity is Severity.ERROR
              or (args.strict and d.severity is Severity.WARNING)]
    if package is None or errors:
        print(f"opspec preprocess: {source} has errors; nothing written", file=sys.stderr)
        return 1
    data = write_xpdl(package)
    if target is None:
        sys.stdout.buffer.write(data)
        return 0
    try:
        write_atomically(target, data)
    except OSError as error:
        print(f"opspec preprocess: {write_problem(target, error)}", file=sys.stderr)
        return 2
    print(f"{target}: standard XPDL 2.1 from {source}")
    copy_user_model("preprocess", source, target)
    for original, copy in copies:
        copy_companion("preprocess", original, copy, "world file")
    return 0
