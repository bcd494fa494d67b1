"""Print the processes, lanes, participants and activities of a spec.

Print what SPEC holds, as readable text or as Graphviz DOT, or draw the whole package as SVG
or as an HTML page. text (the default) prints the package header, participants (human or
system), pools and lanes, modes and their workflows, and every process with its directives,
data, activities (kind, performer, manual or automatic, deadlines, the messages they raise,
their triggers, durations and CPU demands, what a built-in reads and writes) and transitions
with their conditions. dot prints a
Graphviz digraph per process (opspec.xpdl.dot; render it with e.g.
'opspec show SPEC --format dot | dot -Tsvg -o out.svg'). svg and html draw every process with
its lanes and the messages between them in one picture (opspec.xpdl.picture, laid out by
Graphviz's dot program: 'opspec show SPEC --format html -o spec.html' writes the file only
when the picture is drawn; without dot, a one-line error with the install hint and exit
status 2). Every error opspec validate finds is printed on stderr (the spec is still shown),
in a compiled workflow script (.wfs) too: it may have been edited since it was compiled.

Exit status: 0 shown, no errors; 1 shown, but the spec has errors (or the file holds no usable
package); 2 the file cannot be read, the process does not exist, or -o names the spec or a
file it reads (its user model, its world file, a mode's spec; nothing is written then).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from opspec.commands._args import add_spec, command

__all__ = ["describe_package", "load_script", "register", "run"]


def __getattr__(name: str) -> Any:
    # describe_package lives in show_text with the package model it reads, imported when
    # used: registering the command (every `opspec` command builds every parser) imports no
    # model, so that `opspec evaluate` starts its drawing processes before it (issue 31)
    if name == "describe_package":
        from opspec.commands.show_text import describe_package

        return describe_package
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def register(subparsers: Any) -> None:
    parser = command(subparsers, "show", __doc__)
    add_spec(parser)
    parser.add_argument("--format", choices=("text", "dot", "svg", "html"), default="text",
                        help="output format (default: text; svg and html: the whole package "
                        "in one picture)")
    parser.add_argument("--process", metavar="ID", help="only this process (by Id)")
    parser.add_argument("-o", "--output", metavar="FILE",
                        help="write to FILE instead of the standard output ('-': the "
                        "standard output); nothing is "
                        "written (no empty file) when the output cannot be made, e.g. "
                        "without Graphviz")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from opspec.errors import Severity
    from opspec.xpdl.dot import package_to_dot

    if getattr(args, "output", None) == "-":
        args.output = None                  # '-': the standard output (a file named '-' before)
    if str(args.spec).endswith(".wfs"):
        result = _checked_script(args.spec)
    else:
        result = _validated(args.spec)
    package = result.package
    if package is None:
        for diagnostic in result.diagnostics:
            print(diagnostic, file=sys.stderr)
        unreadable = any(d.code == "io-error" for d in result.diagnostics)
        return 2 if unreadable else 1
    if getattr(args, "output", None):
        # -o naming the spec or a file it reads would replace it with the description
        problem = _overwrite_problem(args, package)
        if problem is not None:
            print(problem, file=sys.stderr)
            return 2
    if args.process is not None and package.process(args.process) is None:
        known = ", ".join(repr(p.id) for p in package.processes) or "none"
        print(f"opspec show: {args.spec} has no process {args.process!r} (processes: {known})",
              file=sys.stderr)
        return 2
    errors = [d for d in result.diagnostics if d.severity is Severity.ERROR]
    for diagnostic in errors:
        print(diagnostic, file=sys.stderr)
    if errors:
        count = len(errors)
        # validate reads no script: a script's errors are said as check says them
        said = (f"as 'opspec check {args.spec}' counts them; fix the script or compile its "
                "spec again" if str(args.spec).endswith(".wfs") else
                f"as 'opspec validate {args.spec}' reports them")
        print(f"opspec show: {args.spec} has {count} error{'s' * (count != 1)} (listed above, "
              f"{said}); it cannot run", file=sys.stderr)
    if not package.processes:
        print(f"opspec show: {args.spec} declares no process", file=sys.stderr)
    if args.format in ("svg", "html"):
        from opspec.xpdl.picture import package_picture_dot, picture_html, render_svg

        dot_text = package_picture_dot(package, process=args.process)
        _refuse_huge_picture(args, dot_text)
        svg = render_svg(dot_text, timeout=PICTURE_SECONDS)
        text = svg if args.format == "svg" else picture_html(package, svg)
    elif args.format == "dot":
        text = package_to_dot(package, process=args.process)
    else:
        from opspec.commands.show_text import describe_package

        text = describe_package(package, process=args.process)
    if getattr(args, "output", None):
        _write_whole(Path(args.output), text)
        # as 'opspec compile' does: a file written says so, the standard output being free
        print(f"{args.output}: {args.format} written from {args.spec}")
    else:
        sys.stdout.write(text)
    return 1 if errors else 0


def _overwrite_problem(args: argparse.Namespace, package: Any) -> str | None:
    """Why ``-o`` may not be written: it is the spec, its companion user model, or a file the
    spec reads (its world file, a mode's spec); None when it may."""
    from opspec.commands._files import overwrite_problem, spec_inputs
    from opspec.request import companion_user_model

    spec = Path(args.spec)
    reads = [("SPEC", spec), ("SPEC's companion user model", companion_user_model(spec)),
             *spec_inputs(package.source or spec, package)]
    return overwrite_problem("show", [("-o", Path(args.output))], reads,
                             example=f"{spec.stem}.{_SUFFIXES[args.format]}")


#: The file name suffix suggested for each --format.
_SUFFIXES = {"text": "txt", "dot": "dot", "svg": "svg", "html": "html"}


def _write_whole(path: Path, text: str) -> None:
    """``text`` into ``path`` all at once (a temporary file renamed over it): a failure
    leaves no empty or half-written file."""
    import contextlib
    import os

    from opspec.errors import ConfigurationError

    tmp = path.with_name(f".{path.name}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    except OSError as error:
        # in a "folder" that is a file, removing the temporary file fails as writing did
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        from opspec.commands._files import write_problem

        raise ConfigurationError(write_problem(path, error)) from None


def _validated(path: str) -> Any:
    """The XPDL file ``path`` loaded as ``opspec validate`` loads it, as a
    :class:`~opspec.xpdl.loader.LoadResult` whose diagnostics are every one validate reports
    (the reader's, the structural checks', what the engine refuses)."""
    from opspec.commands.validate import engine_checks
    from opspec.xpdl.loader import LoadResult
    from opspec.xpdl.validate import validate_spec

    unreadable = _unreadable(path)
    if unreadable is not None:
        return LoadResult(None, (unreadable,))
    package, report = validate_spec(path, extra=engine_checks)
    return LoadResult(package, report.diagnostics)


def _unreadable(path: str) -> Any:
    """The ``io-error`` diagnostic for a spec path that is no regular file, or None: said
    here, as the reader would say it, but without calling the file XPDL (it may be BPMN)."""
    from opspec.errors import Diagnostic, Severity, SourceLocation
    from opspec.files import not_a_file
    from opspec.runs import where_to_look

    why = not_a_file(path)
    if why is None:
        return None
    return Diagnostic(SourceLocation(path), Severity.ERROR, "io-error",
                      f"cannot read the file: {why}",
                      where_to_look(path) or
                      "give the path of an XPDL or BPMN spec, or of a compiled .wfs script; "
                      "specs are not read from folders, pipes or devices")


def load_script(path: str) -> Any:
    """A compiled workflow script (``.wfs``) as a :class:`~opspec.xpdl.loader.LoadResult`
    (compiled only from specs without errors, so it carries no diagnostics)."""
    from pathlib import Path

    from opspec.errors import Diagnostic, Severity, SourceLocation, SpecError
    from opspec.model.codec import read_wfs
    from opspec.xpdl.loader import LoadResult

    if not Path(path).is_file():
        what = "is a folder" if Path(path).is_dir() else "does not exist"
        return LoadResult(None, (Diagnostic(SourceLocation(path), Severity.ERROR, "io-error",
                                            f"cannot read the workflow script: it {what}",
                                            "check the path"),))
    try:
        return LoadResult(read_wfs(path))
    except SpecError as error:
        location = error.location or SourceLocation(path, 1)
        message = error.message.removeprefix(f"{path}: ")
        return LoadResult(None, (Diagnostic(location, Severity.ERROR, "bad-script", message,
                                            error.hint or ""),))


def _checked_script(path: str) -> Any:
    """:func:`load_script` with every error ``opspec validate`` finds in the package it
    holds, as ``opspec check`` checks a script: it was compiled from a spec without errors,
    but may have been edited since (a transition to an activity that is not there showed
    with exit status 0, and only ``run`` refused it)."""
    from opspec.commands.validate import engine_checks
    from opspec.errors import Severity
    from opspec.model.checks import check_package
    from opspec.xpdl.loader import LoadResult
    from opspec.xpdl.validate import (
        merge_diagnostics,
        mode_source_diagnostics,
        preprocessed_mode_diagnostics,
    )

    result = load_script(path)
    package = result.package
    if package is None:
        return result
    # as validate_spec checks a package it read: the engine's judgement only of a package
    # the structural checks pass
    checks = [*check_package(package), *mode_source_diagnostics(package),
              *preprocessed_mode_diagnostics(package)]
    if not any(d.severity is Severity.ERROR for d in checks):
        checks.extend(engine_checks(package))
    return LoadResult(package, merge_diagnostics(checks))


#: The largest picture handed to Graphviz, in lines of its input (about one per node and
#: edge): the layout's time and memory grow faster than the graph (a package of some
#: 10,000 activities took minutes and gigabytes), and such a picture is unreadable anyway.
PICTURE_MOST_LINES = 4000
#: How long Graphviz may lay out a picture.
PICTURE_SECONDS = 60.0


def _refuse_huge_picture(args: argparse.Namespace, dot_text: str) -> None:
    lines = dot_text.count("\n")
    if lines > PICTURE_MOST_LINES:
        from opspec.errors import ConfigurationError

        raise ConfigurationError(
            f"{args.spec}: the picture has {lines:,} nodes and edges, more than the "
            f"{PICTURE_MOST_LINES:,} Graphviz is given to lay out",
            hint="draw one process with --process ID, or write the graph with --format dot "
            "and lay it out yourself")
