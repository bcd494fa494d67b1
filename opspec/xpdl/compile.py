"""Compile an XPDL specification into a workflow script (``.wfs``) the engine loads directly.

A spec with errors is refused: compiling it would only move the problem to run time. "Errors"
are exactly what ``opspec validate`` reports (:func:`opspec.xpdl.validate.validate_spec`: the
reader's diagnostics plus the structural checks, and whatever ``extra`` checks the caller adds).
Warnings are returned so the caller can print them; the script is still written.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from opspec.errors import ConfigurationError, Diagnostic, Severity, SpecError
from opspec.model.codec import write_wfs
from opspec.model.package import Package
from opspec.xpdl.validate import validate_spec

__all__ = ["CompileResult", "compile_spec", "compiled_package", "default_output"]


@dataclass(frozen=True, slots=True)
class CompileResult:
    """The compiled package, where it was written and the (non-error) diagnostics."""

    package: Package
    output: Path
    diagnostics: tuple[Diagnostic, ...] = ()


def default_output(source: str | os.PathLike[str]) -> Path:
    """``IN`` with its suffix replaced by ``.wfs`` (``specs/a.xpdl`` -> ``specs/a.wfs``)."""
    return Path(source).with_suffix(".wfs")


def compile_spec(
    source: str | os.PathLike[str],
    output: str | os.PathLike[str] | None = None,
    *,
    strict: bool = False,
    extra: Callable[[Package], Iterable[Diagnostic]] | None = None,
) -> CompileResult:
    """Validate the XPDL in ``source`` as ``opspec validate`` does and write its ``.wfs`` to
    ``output`` (default: :func:`default_output`).

    Raises :class:`SpecError` carrying every diagnostic when the spec has errors (``strict``
    counts warnings as errors; ``extra`` adds checks of layers above, as in
    :func:`~opspec.xpdl.validate.validate_spec`); nothing is written then. An ``output`` that
    is ``source`` itself (or a link to it) is a :class:`ConfigurationError`. ``OSError`` from
    writing propagates.
    """
    target = Path(output) if output is not None else default_output(source)
    if target.exists() and Path(source).exists() and os.path.samefile(source, target):
        raise ConfigurationError(f"the output {target} is the input file itself",
                                 hint="write the compiled script to another file")
    package, warnings = compiled_package(source, strict=strict, extra=extra)
    write_wfs(package, target)
    return CompileResult(package, target, warnings)


def compiled_package(
    source: str | os.PathLike[str],
    *,
    strict: bool = False,
    extra: Callable[[Package], Iterable[Diagnostic]] | None = None,
) -> tuple[Package, tuple[Diagnostic, ...]]:
    """The package :func:`compile_spec` writes, and its warnings; nothing is written.
    Raises :class:`SpecError` as :func:`compile_spec` does."""
    package, report = validate_spec(Path(source), strict=strict, extra=extra)
    if package is None or not report.ok:
        raise SpecError.from_diagnostics(report.diagnostics)
    warnings = tuple(d for d in report.diagnostics if d.severity is not Severity.ERROR)
    return package, warnings
