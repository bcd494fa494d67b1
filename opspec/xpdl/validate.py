"""Validation of specification files: the reader's diagnostics plus the model's structural checks.

:func:`validate_file` loads one file with :func:`opspec.xpdl.loader.load_package` (which never
raises for bad input), runs :func:`opspec.model.checks.check_package` on the package it gets,
merges both lists (a problem both report is listed once) and returns a :class:`FileReport`.
:func:`spec_files` expands the command line's files and folders. The rest formats reports as
``path:line: severity: message (hint)`` lines or JSON objects; ``opspec validate`` is a thin
wrapper around this module.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model import Package
from opspec.model.checks import check_package
from opspec.xpdl.loader import load_package
from opspec.xpdl.reader import DEFAULT_MAX_BYTES

__all__ = [
    "MODE_SOURCE_OUTSIDE",
    "SPEC_SUFFIXES",
    "FileReport",
    "merge_diagnostics",
    "mode_source_diagnostics",
    "preprocessed_mode_diagnostics",
    "spec_files",
    "summary",
    "validate_file",
    "validate_spec",
]

SPEC_SUFFIXES = (".xpdl", ".xml", ".bpmn")

# Codes that mean "the file could not be read at all" (exit status 2, not 1).
IO_CODES = frozenset({"io-error"})

# Reader code -> check code for the same problem at the same place: the reader's wins.
_SAME_PROBLEM = {"unresolved-subflow": "undefined-subflow"}


@dataclass(frozen=True, slots=True)
class FileReport:
    """The outcome of validating one file.

    ``version`` is the XPDL version read from the root namespace (``"1.0"``, ``"2.1"``,
    ``"none"``…), ``"BPMN 2.0"`` for a BPMN file, or ``None`` when no package could be
    built. ``diagnostics`` may include
    problems of other files the package refers to (each carries its own path).
    """

    path: str
    version: str | None
    diagnostics: tuple[Diagnostic, ...]

    @property
    def ok(self) -> bool:
        """No error (warnings allowed, unless strict mode promoted them)."""
        return not any(d.severity is Severity.ERROR for d in self.diagnostics)

    @property
    def unreadable(self) -> bool:
        """The file could not be read (missing, permission denied): an I/O problem."""
        return any(d.code in IO_CODES for d in self.diagnostics)

    def count(self, severity: Severity) -> int:
        return sum(1 for d in self.diagnostics if d.severity is severity)

    def to_json(self) -> dict[str, object]:
        """The ``--json`` object: ``path``, ``version``, ``ok`` and ``diagnostics`` (each with
        ``path``, ``line``, ``severity``, ``code``, ``message`` and ``hint``)."""
        return {
            "path": self.path,
            "version": self.version,
            "ok": self.ok,
            "diagnostics": [d.to_json() for d in self.diagnostics],
        }

    def lines(self) -> list[str]:
        """One ``path:line: severity: message (hint)`` line per diagnostic."""
        return [str(d) for d in self.diagnostics]


def merge_diagnostics(*groups: Iterable[Diagnostic]) -> tuple[Diagnostic, ...]:
    """Concatenate ``groups`` (reader first), dropping repeats, sorted by file and line.

    A repeat is a diagnostic with the same path, line, code and message as an earlier one, or
    a check that restates a reader diagnostic at the same place under another code
    (``undefined-subflow`` after ``unresolved-subflow``). The sort is stable, so problems on
    one line keep their order; diagnostics without a line come first in their file.
    """
    seen: set[tuple[str, int | None, str, str]] = set()
    places: set[tuple[str, int | None, str]] = set()
    out: list[Diagnostic] = []
    for group in groups:
        for diagnostic in group:
            where = (diagnostic.location.path, diagnostic.location.line)
            key = (*where, diagnostic.code, diagnostic.message)
            if key in seen or (*where, diagnostic.code) in places:
                continue
            seen.add(key)
            restated = _SAME_PROBLEM.get(diagnostic.code)
            if restated is not None:
                places.add((*where, restated))
            out.append(diagnostic)
    order = {path: n for n, path in enumerate(dict.fromkeys(d.location.path for d in out))}
    out.sort(key=lambda d: (order[d.location.path], d.location.line or 0))
    return tuple(out)


def _promote(diagnostics: Iterable[Diagnostic]) -> tuple[Diagnostic, ...]:
    return tuple(
        dataclasses.replace(d, severity=Severity.ERROR) if d.severity is Severity.WARNING else d
        for d in diagnostics)


#: The code of a mode Source leading outside the spec's folder tree (docs/validation.md).
MODE_SOURCE_OUTSIDE = "mode-source-outside"


def mode_source_diagnostics(package: Package, *, max_bytes: int = DEFAULT_MAX_BYTES
                            ) -> list[Diagnostic]:
    """Errors of the specs that modes load at run time (``<opspec:Mode Source="…">``,
    relative to the package's file): a missing file, or the loaded spec's own reader errors,
    each at the line of the mode (the engine would only find them at the mode change)."""
    from opspec.files import companion_outside, not_a_file

    base = Path(package.source).parent if package.source else Path.cwd()
    out: list[Diagnostic] = []
    for mode in package.modes:
        if not mode.source:
            continue
        where = mode.location or SourceLocation(package.source or "<spec>")
        outside = companion_outside(package.source, mode.source, f"mode {mode.id!r}: Source")
        if outside is not None:          # refused before the file is even looked at
            out.append(Diagnostic(where, Severity.ERROR, MODE_SOURCE_OUTSIDE, *outside))
            continue
        target = base / mode.source
        why = not_a_file(target)
        if why is not None:
            out.append(Diagnostic(
                where, Severity.ERROR, "bad-mode",
                f"mode {mode.id!r} loads {mode.source!r}, which does not exist ({target})"
                if why == "it does not exist" else
                f"mode {mode.id!r} loads {mode.source!r}, which cannot be read: {why}",
                "Source is relative to this spec's folder; fix the name or add the file"))
            continue
        loaded = load_package(target, max_bytes=max_bytes)
        errors = [d for d in loaded.diagnostics if d.severity is Severity.ERROR]
        if loaded.package is None or errors:
            first = errors[0] if errors else None
            out.append(Diagnostic(
                where, Severity.ERROR, "bad-mode",
                f"mode {mode.id!r} loads {mode.source!r}, which has errors"
                + (f" (first: {first})" if first is not None else ""),
                f"run opspec validate {target}"))
    return out


def preprocessed_mode_diagnostics(package: Package) -> list[Diagnostic]:
    """Mode changes written as preprocessed tasks (``TaskApplication
    Id="opspec.engine.mode_change"`` with a string literal, see ``opspec preprocess``) to a
    mode the package does not declare: the check the SISARL built-in gets, for the task the
    engine runs in its place."""
    from opspec.model.activities import Task
    from opspec.model.expressions import Literal

    declared = {mode.id for mode in package.modes}
    out: list[Diagnostic] = []
    for process in package.processes:
        for activity in process.all_activities():
            body = activity.body
            if not isinstance(body, Task) or not body.applications:
                continue
            call = body.applications[0]
            if call.application != "opspec.engine.mode_change" or not call.actual_parameters:
                continue
            target = call.actual_parameters[0].expression
            if isinstance(target, Literal) and isinstance(target.value, str) and (
                    target.value not in declared):
                out.append(Diagnostic(
                    activity.location or SourceLocation(package.source or "<spec>"),
                    Severity.ERROR, "undefined-mode",
                    f"activity {activity.id!r} in process {process.id!r} changes to mode "
                    f"{target.value!r}, which the package does not declare",
                    "declare it in opspec:Modes or fix the target mode"))
    return out


def validate_file(path: str | Path, *, strict: bool = False,
                  max_bytes: int = DEFAULT_MAX_BYTES,
                  extra: Callable[[Package], Iterable[Diagnostic]] | None = None
                  ) -> FileReport:
    """Load ``path`` and check its package; never raises for bad input.

    ``strict`` turns every warning (the reader's and the checks') into an error. ``extra``
    runs further checks on a package that has no errors so far (layers above this one check
    what only they understand, e.g. the text of ``opspec:Monitor``).
    """
    return validate_spec(path, strict=strict, max_bytes=max_bytes, extra=extra)[1]


def validate_spec(path: str | Path, *, strict: bool = False,
                  max_bytes: int = DEFAULT_MAX_BYTES,
                  extra: Callable[[Package], Iterable[Diagnostic]] | None = None
                  ) -> tuple[Package | None, FileReport]:
    """:func:`validate_file`, also giving the package it loaded (``None`` when none could be
    built): the commands that run a spec refuse it when the report is not ``ok``."""
    result = load_package(path, max_bytes=max_bytes)
    checks: list[Diagnostic] = []
    version = None
    if result.package is not None:
        # a BPMN file is reported as such ("BPMN 2.0"), not as the XPDL version of its model
        version = result.package.header.source_format or result.package.version.value
        checks = list(check_package(result.package, packages=result.packages))
        checks.extend(mode_source_diagnostics(result.package, max_bytes=max_bytes))
        checks.extend(preprocessed_mode_diagnostics(result.package))
        if extra is not None and not any(
                d.severity is Severity.ERROR for d in (*result.diagnostics, *checks)):
            checks.extend(extra(result.package))
    diagnostics = merge_diagnostics(result.diagnostics, checks)
    if strict:
        diagnostics = _promote(diagnostics)
    return result.package, FileReport(str(path), version, diagnostics)


def spec_files(paths: Sequence[str | Path], *,
               where_to_look: Callable[[Path], str | None] | None = None
               ) -> tuple[list[Path], list[str]]:
    """The files to validate, and a problem line for every argument that cannot be used.

    A file argument is taken as it is (whatever its suffix); a folder contributes every
    ``*.xpdl`` and ``*.xml`` file below it, recursively, sorted. A missing path, a folder
    holding no such file, or a broken symbolic link with such a name in a folder gives a
    problem; ``where_to_look`` adds to a missing path's where it was looked for (the
    commands' :func:`opspec.runs.where_to_look`). Files named twice are validated once.
    (``*.bpmn`` files are BPMN 2.0; what a file holds is decided by its content, so any of
    them may be either.)
    """
    files: list[Path] = []
    problems: list[str] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            named = sorted(p for p in path.rglob("*") if p.suffix.lower() in SPEC_SUFFIXES)
            found = [p for p in named if p.is_file()]
            # A spec-named link whose target is gone is reported, not silently skipped.
            broken = [p for p in named if p.is_symlink() and not p.exists()]
            for link in broken:
                problems.append(f"{link}: broken symbolic link (its target {_target(link)} "
                                "does not exist)")
            if not found and not broken:
                problems.append(f"{path}: no *.xpdl or *.xml file (or *.bpmn) in this folder")
            files.extend(found)
        elif path.exists():
            files.append(path)
        else:
            hint = where_to_look(path) if where_to_look is not None else None
            problems.append(f"{path}: no such file or folder" + (f" ({hint})" if hint else ""))
    return list(dict.fromkeys(files)), problems


def _target(link: Path) -> str:
    try:
        return str(link.readlink())
    except OSError:
        return "?"


def summary(reports: Sequence[FileReport], beside: Sequence[str] = (),
            only_read: Sequence[str] = (), given: Sequence[str] = (),
            given_only_read: Sequence[str] = ()) -> str:
    """``3 files checked: 1 with errors (4 errors, 2 warnings)`` and the like; ``beside``
    names the files checked with the specs (``1 file checked with pill.users.toml beside it:
    …``), ``only_read`` those that could not be checked against a spec with errors (more than
    four are counted); ``given`` and ``given_only_read`` the same of a user model given with
    ``--user-model`` (``… with pill.population.toml as its user model``)."""
    files = len(reports)
    errors = sum(r.count(Severity.ERROR) for r in reports)
    warnings = sum(r.count(Severity.WARNING) for r in reports)
    failed = sum(1 for r in reports if not r.ok)
    noun = "file" if files == 1 else "files"

    def plural(n: int, word: str) -> str:
        return f"{n} {word}{'' if n == 1 else 's'}"

    if failed:
        verdict = f"{failed} with errors"
    else:
        verdict = "no errors"
    def listed(names: Sequence[str]) -> str:
        return ", ".join(names) if len(names) <= 4 else plural(len(names), "side file")

    checked = f"{files} {noun} checked"
    if beside:
        checked += f" with {listed(beside)} beside {'it' if files == 1 else 'them'}"
    if only_read:
        checked += (f" ({listed(only_read)} beside {'it' if files == 1 else 'them'} only read: "
                    f"{'the spec has' if files == 1 else 'their spec has'} errors)")
    model = "its user model" if files == 1 else "their user model"
    if given:
        checked += f" with {listed(given)} as {model}"
    if given_only_read:
        checked += (f" ({listed(given_only_read)} as {model} only read: "
                    f"{'the spec has' if files == 1 else 'their spec has'} errors)")
    return (f"{checked}: {verdict} "
            f"({plural(errors, 'error')}, {plural(warnings, 'warning')})")
