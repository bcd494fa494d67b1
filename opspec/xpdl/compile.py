"""Compile an XPDL specification into a workflow script (``.wfs``) the engine loads directly.

A spec with errors is refused: compiling it would only move the problem to run time. Warnings
are returned so the caller can print them; the script is still written.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from opspec.errors import Diagnostic, SpecError
from opspec.model.codec import write_wfs
from opspec.model.package import Package
from opspec.xpdl.loader import load_package

__all__ = ["CompileResult", "compile_spec", "default_output"]


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
) -> CompileResult:
    """Load the XPDL in ``source`` and write its ``.wfs`` to ``output`` (default:
    :func:`default_output`).

    Raises :class:`SpecError` carrying every diagnostic when the spec has errors (``strict``
    counts warnings as errors); nothing is written then. ``OSError`` from writing propagates.
    """
    result = load_package(Path(source), strict=strict)
    if not result.ok or result.package is None:
        raise SpecError.from_diagnostics(result.diagnostics)
    target = Path(output) if output is not None else default_output(source)
    write_wfs(result.package, target)
    return CompileResult(result.package, target, result.diagnostics)
