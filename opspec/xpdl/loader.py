"""The public entry points of the XPDL front end.

``load_package`` never raises for bad input: whatever the file holds (hostile XML, binary
garbage, a truncated export, reference cycles) the result is a :class:`LoadResult` whose
diagnostics say what is wrong and where. ``load_spec`` is the raising variant for commands that
need a usable package.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

from opspec.errors import Diagnostic, Severity, SourceLocation, SpecError
from opspec.model.bulk import gc_paused
from opspec.model.package import Package
from opspec.xpdl.handlers import BuildContext, build_package
from opspec.xpdl.normalize import normalize
from opspec.xpdl.reader import (
    DEFAULT_MAX_BYTES,
    XmlReadError,
    exact_lines,
    parse_safely,
    read_file,
    xpdl_outcome,
)
from opspec.xpdl.resolve import resolve

__all__ = ["LoadResult", "load_package", "load_spec", "parse_bytes"]

_EMPTY: Mapping[str, Package] = MappingProxyType({})


@dataclass(frozen=True, slots=True)
class LoadResult:
    """What loading a specification gave.

    ``package`` is the root package (``None`` when the file could not be read as XPDL at
    all); ``packages`` maps package Id to every package loaded (the root plus resolved external
    and subflow packages); ``diagnostics`` lists every problem found, each with file:line.
    """

    package: Package | None
    diagnostics: tuple[Diagnostic, ...] = ()
    packages: Mapping[str, Package] = field(default_factory=lambda: _EMPTY)

    @property
    def ok(self) -> bool:
        """True when a package was built and no diagnostic is an error."""
        return self.package is not None and not any(
            d.severity is Severity.ERROR for d in self.diagnostics
        )

    @property
    def errors(self) -> tuple[Diagnostic, ...]:
        return tuple(d for d in self.diagnostics if d.severity is Severity.ERROR)


def _internal(path: str, error: BaseException) -> Diagnostic:
    return Diagnostic(
        SourceLocation(path), Severity.ERROR, "internal-error",
        f"opspec could not read this file ({type(error).__name__}: {error})",
        "this is a bug in opspec; please report it with the file",
    )


def _build(data: bytes, path: str, max_bytes: int) -> tuple[Package | None, list[Diagnostic]]:
    """Read, normalise and build one file; never raises (except MemoryError/KeyboardInterrupt).

    What the file is goes by its content, not its name: a BPMN 2.0 ``definitions`` root is
    built by :mod:`opspec.xpdl.bpmn` into the same model, anything else is read as XPDL."""
    from opspec.xpdl.bpmn import BPMN_VERSION, build_bpmn, is_bpmn
    from opspec.xpdl.gate import gate_diagnostics, gate_findings

    try:
        parsed = parse_safely(data, path=path, max_bytes=max_bytes)
        bpmn = is_bpmn(parsed.root)
        outcome = None if bpmn else xpdl_outcome(parsed, path=path)
    except XmlReadError as error:
        return None, [error.diagnostic()]
    version = BPMN_VERSION if outcome is None else outcome.version
    ctx = BuildContext(path=path, version=version, diagnostics=list(parsed.warnings))
    try:
        with exact_lines(parsed):            # lines past 65,534 (libxml2 stores 16 bits)
            # the semantics gate reads the file as written, before the build rewrites it
            findings = gate_findings(parsed.root if outcome is None else outcome.root, path)
            if outcome is None:
                package = build_bpmn(parsed.root, ctx)
            else:
                package = build_package(normalize(outcome.root), ctx)
    except (MemoryError, KeyboardInterrupt):
        raise
    except Exception as error:  # noqa: BLE001 - a user never sees a traceback (issue 2)
        return None, [*ctx.diagnostics, _internal(path, error)]
    return package, [*ctx.diagnostics, *gate_diagnostics(findings, ctx.diagnostics)]


def _load_file(path: Path, max_bytes: int) -> tuple[Package | None, list[Diagnostic]]:
    try:
        data = read_file(path, max_bytes=max_bytes)
    except XmlReadError as error:
        return None, [error.diagnostic()]
    return _build(data, str(path), max_bytes)


def _strict(diagnostics: list[Diagnostic], strict: bool) -> tuple[Diagnostic, ...]:
    if not strict:
        return tuple(diagnostics)
    return tuple(
        dataclasses.replace(d, severity=Severity.ERROR) if d.severity is Severity.WARNING else d
        for d in diagnostics
    )


def parse_bytes(
    data: bytes, *, path: str = "<bytes>", strict: bool = False, max_bytes: int = DEFAULT_MAX_BYTES
) -> LoadResult:
    """Load one package from bytes, without resolving references to other files."""
    with gc_paused():
        package, diagnostics = _build(data, path, max_bytes)
    packages = MappingProxyType({package.id: package}) if package is not None else _EMPTY
    return LoadResult(package, _strict(diagnostics, strict), packages)


def load_package(
    path: str | Path, *, strict: bool = False, max_bytes: int = DEFAULT_MAX_BYTES
) -> LoadResult:
    """Load the package in ``path`` and every package it refers to.

    Never raises for bad input: fatal problems give ``package=None`` and an error diagnostic.
    ``strict`` turns warnings into errors. ``max_bytes`` limits the size of every file read.
    """
    with gc_paused():       # a big file: no full collections while its model is built
        return _load_package(Path(path), strict, max_bytes)


def _load_package(file: Path, strict: bool, max_bytes: int) -> LoadResult:
    def load(target: Path) -> tuple[Package | None, list[Diagnostic]]:
        return _load_file(target, max_bytes)

    package, diagnostics = load(file)
    if package is None:
        return LoadResult(None, _strict(diagnostics, strict), _EMPTY)
    try:
        resolution = resolve(package, file, load)
    except (MemoryError, KeyboardInterrupt):
        raise
    except Exception as error:  # noqa: BLE001 - see _build
        diagnostics.append(_internal(str(file), error))
        return LoadResult(package, _strict(diagnostics, strict),
                          MappingProxyType({package.id: package}))
    diagnostics.extend(resolution.diagnostics)
    return LoadResult(package, _strict(diagnostics, strict), MappingProxyType(resolution.packages))


def load_spec(path: str | Path, *, strict: bool = False, max_bytes: int = DEFAULT_MAX_BYTES) -> Package:
    """The package in ``path``; raises :class:`SpecError` listing every error if there are any."""
    result = load_package(path, strict=strict, max_bytes=max_bytes)
    if not result.ok or result.package is None:
        raise SpecError.from_diagnostics(result.diagnostics or (
            Diagnostic(SourceLocation(str(path)), Severity.ERROR, "unreadable", "cannot load"),))
    return result.package
