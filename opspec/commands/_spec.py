"""What several commands share: a spec through the front hall's gate (:mod:`opspec.request`),
and what only the engine can judge of a spec, as validate's diagnostics."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

from opspec.errors import ConfigurationError
from opspec.model.nesting import MAX_BLOCK_NESTING, nesting_problem

if TYPE_CHECKING:
    from opspec.errors import Diagnostic
    from opspec.model import Package

__all__ = ["MAX_BLOCK_NESTING", "companion_user_model", "engine_diagnostics", "load_any_spec",
           "nesting_problem", "where_to_look"]


def load_any_spec(path: str | Path, *, command: str | None = None,
                  warnings: list[str] | None = None) -> Package:
    """The package in ``path`` through the front hall's gate
    (:func:`opspec.request.open_gated`: any form, refused with every error ``opspec validate``
    reports). With ``command`` (``"run"``, ``"evaluate"``), validate's warnings are printed to
    stderr as ``opspec COMMAND: path:line: warning: ...``: a misspelt directive changes what
    runs, and must not pass unseen. ``warnings``, when given, receives each warning's text
    (the walkthrough shows them on its screen)."""
    from opspec.request import open_gated

    package, found = open_gated(path)
    for warning in found:
        if command is not None:
            print(f"opspec {command}: {warning}", file=sys.stderr)
        if warnings is not None:
            warnings.append(str(warning))
    return package


def where_to_look(path: Path) -> str | None:
    """:func:`opspec.runs.where_to_look`, imported only for a path that is missing (the
    front hall's imports are not what ``validate`` and ``check`` start with)."""
    from opspec.runs import where_to_look as where

    return where(path)


# The code of what the engine's compilation refuses (compile_package's SpecError).
NOT_RUNNABLE = "not-runnable"


def engine_diagnostics(package: Package, *, world: bool = False) -> list[Diagnostic]:
    """What only the engine and the bindings can judge, as diagnostics: whether the engine
    compiles the package at all (``not-runnable``: what ``run`` would refuse, at its line),
    the monitors the spec declares (``bad-monitor``) and, with ``world``, whether its world
    can be built (``bad-world``: an unknown world, a missing opspec:WorldFile, an unknown parameter, a
    value of the wrong type, a start inside an obstacle)."""
    from opspec.engine.compiled import compile_package
    from opspec.errors import Diagnostic, OpspecError, Severity, SourceLocation
    from opspec.properties.monitors import declared_monitors

    spec_file = SourceLocation(str(getattr(package, "source", None) or "<spec>"))
    deep = nesting_problem(package)
    if deep is not None:        # the compiler follows blocks recursively: stop before it
        return [Diagnostic(deep.location or spec_file, Severity.ERROR, NOT_RUNNABLE,
                           deep.message, deep.hint)]
    try:
        compiled = compile_package(package)
    except OpspecError as error:
        # what the engine refuses, validate refuses: at its line, as the run would say it
        return [Diagnostic(error.location or spec_file, Severity.ERROR, NOT_RUNNABLE,
                           error.message, error.hint or "")]
    out: list[Diagnostic] = [
        Diagnostic(metric.location or spec_file, Severity.WARNING, "metric-name",
                   f"metric name {metric.name!r} is not a simple identifier; the file names "
                   "of its figures (opspec evaluate) use a changed name",
                   "name metrics with letters, digits and '_', starting with a letter, "
                   "such as doses_missed")
        for metric in getattr(package, "metrics", ()) if not _simple(metric.name)]
    try:
        declared_monitors(compiled)
    except ConfigurationError as error:
        out.append(Diagnostic(error.location or spec_file, Severity.ERROR, "bad-monitor",
                              error.message, error.hint or ""))
    if world:
        # the world is built to be judged, not run: its devices (and the engine's activity
        # runner that the room's devices subclass) are not imported
        from opspec.worlds import check_world

        try:
            check_world(compiled, seed=0)
        except ConfigurationError as error:
            out.append(Diagnostic(error.location or spec_file, Severity.ERROR, "bad-world",
                                  error.message, error.hint or ""))
    return out


def _simple(name: str) -> bool:
    """A simple identifier: ASCII letters, digits and ``_``, not starting with a digit."""
    return name.isascii() and name.isidentifier()


def companion_user_model(spec_path: str | Path) -> Path | None:
    """``SPEC.users.toml`` next to the spec, if there is one (the front hall's rule)."""
    from opspec.request import companion_user_model as companion

    return companion(spec_path)
