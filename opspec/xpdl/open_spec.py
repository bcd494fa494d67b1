"""Open a specification whatever its form: an XPDL file or a compiled workflow script (.wfs)."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

from opspec.errors import ConfigurationError, Diagnostic, Severity, SourceLocation, SpecError
from opspec.model import Package

__all__ = ["IO_CODES", "SPEC_SUFFIXES", "mode_loader_for", "open_spec", "refuse_folder",
           "refuse_unreadable", "unreadable"]


def open_spec(path: str | Path) -> Package:
    """The package in ``path`` (``.wfs`` scripts load directly, anything else as XPDL).

    Raises :class:`~opspec.errors.SpecError` (with ``path:line``) for a broken spec and
    :class:`~opspec.errors.ConfigurationError` (exit status 2) for a path that is not a
    readable regular file: missing, a folder, a pipe or device (refused without blocking),
    or unreadable.
    """
    from opspec.xpdl.reader import not_a_file

    target = Path(path)
    reason = not_a_file(target)
    if reason is not None:
        if reason == "it is a folder":
            refuse_folder(target)
        what = {"it does not exist": "not found"}.get(reason, f"cannot read it: {reason}")
        raise ConfigurationError(f"{target}: {what}; give one specification file",
                                 hint="e.g. specs/medication_dispenser.xpdl")
    if target.suffix == ".wfs":
        from opspec.model.codec import read_wfs

        unreadable(target)
        return read_wfs(target)
    from opspec.xpdl.loader import load_package

    result = load_package(target)
    refuse_unreadable(result.diagnostics)
    if not result.ok or result.package is None:
        raise SpecError.from_diagnostics(result.diagnostics or (
            Diagnostic(SourceLocation(str(path)), Severity.ERROR, "unreadable", "cannot load"),))
    return result.package


#: What a specification file's name ends with, for the files a folder is told to hold.
SPEC_SUFFIXES = (".xpdl", ".bpmn", ".wfs")
#: How many of a folder's spec files a refusal names.
_NAMED = 4


def refuse_folder(folder: Path) -> None:
    """Raise the :class:`ConfigurationError` for a folder given where a spec file is meant,
    naming the spec files in it (a command never picks one itself: which one is meant is the
    user's to say)."""
    try:
        names = sorted(entry.name for entry in folder.iterdir()
                       if entry.suffix.lower() in SPEC_SUFFIXES
                       and not entry.name.startswith(".") and entry.is_file())
    except OSError:
        names = []
    files = [str(folder / name) for name in names]
    if len(files) == 1:
        raise ConfigurationError(f"{folder}: a folder; give the spec file: {files[0]}")
    if files:
        shown = files if len(files) <= _NAMED + 1 else files[:_NAMED]
        more = f" (and {len(files) - len(shown)} more)" if len(shown) < len(files) else ""
        raise ConfigurationError(f"{folder}: a folder; give one specification file: "
                                 f"{', '.join(shown)}{more}")
    raise ConfigurationError(f"{folder}: a folder; give one specification file",
                             hint="e.g. specs/medication_dispenser.xpdl")


#: Diagnostic codes meaning "the file could not be read at all" (exit status 2, not 1).
IO_CODES = frozenset({"io-error"})


def refuse_unreadable(diagnostics: Iterable[Diagnostic]) -> None:
    """Raise a :class:`ConfigurationError` (exit status 2) for the first diagnostic saying a
    file could not be read (``io-error``): an I/O problem, not an error in a spec."""
    for diagnostic in diagnostics:
        if diagnostic.code in IO_CODES:
            raise ConfigurationError(diagnostic.message, location=diagnostic.location,
                                     hint=diagnostic.hint)


def unreadable(path: Path) -> None:
    """Raise a :class:`ConfigurationError` when ``path`` cannot be opened for reading as a
    regular file (permissions, a pipe); opening never blocks."""
    from opspec.files import open_regular

    try:
        with open_regular(path):
            pass
    except OSError as error:
        raise ConfigurationError(
            f"cannot read the file: {error.strerror or type(error).__name__}",
            location=SourceLocation(str(path)), hint="check the path and its permissions",
        ) from None


def mode_loader_for(package: Package) -> Callable[[str], Package]:
    """A loader for the specs a package's modes name (``<opspec:Mode Source="dock.xpdl">``),
    relative to the package's own file, each read once. The engine compiles what it returns
    when the mode is first entered.

    A Source leading outside the spec's folder tree (and ``OPSPEC_EXTERNAL_PATH``) is refused
    at once, as ``opspec validate`` refuses it (``mode-source-outside``, a
    :class:`~opspec.errors.SpecError` at the mode's line), not when the mode is entered; a
    loader asked for such a file anyway refuses it the same way."""
    from opspec.files import companion_outside

    base = Path(package.source).parent if package.source else Path.cwd()
    cache: dict[str, Package] = {}

    def refuse_outside(source: str, where: SourceLocation | None, what: str) -> None:
        outside = companion_outside(package.source, source, what)
        if outside is not None:
            raise SpecError.from_diagnostics([Diagnostic(
                where or SourceLocation(package.source or "<spec>"), Severity.ERROR,
                "mode-source-outside", *outside)])

    for mode in package.modes:
        if mode.source:
            refuse_outside(mode.source, mode.location, f"mode {mode.id!r}: Source")

    def load(source: str) -> Package:
        if source not in cache:
            refuse_outside(source, None, "a mode's Source")
            cache[source] = open_spec(base / source)
        return cache[source]

    return load
