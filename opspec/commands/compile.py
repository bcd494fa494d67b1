"""Compile a spec (XPDL or BPMN) into a workflow script (.wfs) the engine loads.

Load IN (XPDL, SISARL-XPDL or BPMN 2.0), refuse it if it has errors, and write its compiled
workflow script (versioned JSON, docs/wfs-format.md). The spec's companion user model
IN.users.toml is copied to OUT.users.toml (an existing different file is kept), so that
opspec run OUT draws the same users as opspec run IN.

Exit status: 0 written (warnings are printed); 1 the spec has errors, exactly those opspec
validate reports (each printed as 'path:line: severity: message'; nothing is written); 2 the
input cannot be read (missing, a folder, a pipe or device, no permission) or is a compiled
script already, the output is a file the spec reads (itself, its user model, its world file, a
mode's spec), or the output cannot be written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from opspec.commands._args import add_translation, command

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = command(subparsers, "compile", __doc__)
    add_translation(parser, "XPDL or BPMN", "OUT.wfs", "IN with the suffix .wfs; '-' for stdout")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from opspec.commands._companions import copy_user_model
    from opspec.commands._files import (
        input_problem,
        overwrite_problem,
        same_file,
        spec_inputs,
        translation_problem,
        write_problem,
    )
    from opspec.commands.validate import engine_checks
    from opspec.errors import SpecError
    from opspec.model.codec import dumps, write_wfs
    from opspec.xpdl.compile import compiled_package, default_output

    source = Path(args.input)
    # -o -: the script on the standard output, as preprocess -o - writes its XPDL (its spec's
    # path is written as given, so it holds for a script saved in the current folder; no
    # user model is copied)
    target = None if args.output == "-" else (
        Path(args.output) if args.output else default_output(source))
    if (target is not None and source.suffix == ".wfs" and same_file(source, target)
            and input_problem(source) is None):
        # IN.wfs is its own default output: there is nothing to compile, not an -o to change
        given = f"-o {args.output} is IN itself, and " if args.output else ""
        print(_already_compiled(source, given), file=sys.stderr)
        return 2
    problem = translation_problem("compile", source, target,
                                  example=f"{source.with_suffix('.wfs').name} beside it")
    if problem is not None:
        print(problem, file=sys.stderr)
        return 2
    try:
        package, warnings = compiled_package(source, strict=args.strict, extra=engine_checks)
    except SpecError as error:
        return _refused(error, source)
    if target is None:
        for diagnostic in warnings:
            print(diagnostic, file=sys.stderr)
        sys.stdout.write(dumps(package) + "\n")
        return 0
    # -o naming a file the spec reads (its world file, a mode's spec) would replace it
    problem = overwrite_problem("compile", [("-o", target)], spec_inputs(source, package),
                                example=f"{source.with_suffix('.wfs').name} beside it")
    if problem is not None:
        print(problem, file=sys.stderr)
        return 2
    try:
        write_wfs(package, target)
    except OSError as error:
        print(f"opspec compile: {write_problem(target, error)}", file=sys.stderr)
        return 2
    for diagnostic in warnings:
        print(diagnostic, file=sys.stderr)
    print(f"{target}: compiled from {source}")
    # a run of OUT looks for OUT.users.toml: without it, the user lane of a script compiled
    # to another name would run with nobody on it
    copy_user_model("compile", source, target)
    return 0


def _already_compiled(source: Path, given: str = "") -> str:
    return (f"opspec compile: {given}{source} is already compiled (a workflow script, .wfs); "
            "nothing written. Compile the XPDL it was compiled from, or use "
            f"{source} as it is: opspec show, run and evaluate read it directly")


def _refused(error: Any, source: Path) -> int:
    """Print why IN was not compiled (a :class:`SpecError`'s diagnostics, then one line);
    the exit status: 2 when IN cannot be read or is a compiled script itself (the wrong
    file, not a spec with errors), else 1."""
    from opspec.xpdl.open_spec import IO_CODES

    diagnostics = error.diagnostics or ()
    if any(d.code == "compiled-script" for d in diagnostics):
        print(_already_compiled(source), file=sys.stderr)
        return 2
    for diagnostic in diagnostics:
        print(diagnostic, file=sys.stderr)
    if not diagnostics:
        print(f"opspec compile: {error}", file=sys.stderr)
    if any(d.code in IO_CODES for d in diagnostics):
        print(f"opspec compile: cannot read {source}; nothing written", file=sys.stderr)
        return 2
    print(f"opspec compile: {source} has errors; nothing written", file=sys.stderr)
    return 1
