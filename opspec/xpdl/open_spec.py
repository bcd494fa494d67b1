"""Open a specification whatever its form: an XPDL file or a compiled workflow script (.wfs)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from opspec.errors import ConfigurationError
from opspec.model import Package

__all__ = ["mode_loader_for", "open_spec"]


def open_spec(path: str | Path) -> Package:
    """The package in ``path`` (``.wfs`` scripts load directly, anything else as XPDL).

    Raises :class:`~opspec.errors.SpecError` (with ``path:line``) for a broken spec and
    :class:`~opspec.errors.ConfigurationError` for a path that is not a readable file.
    """
    target = Path(path)
    if not target.is_file():
        what = "a folder" if target.is_dir() else "not found"
        raise ConfigurationError(f"{target}: {what}; give one specification file",
                                 hint="e.g. specs/medication_dispenser.xpdl")
    if target.suffix == ".wfs":
        from opspec.model.codec import read_wfs

        return read_wfs(target)
    from opspec.xpdl.loader import load_spec

    return load_spec(target)


def mode_loader_for(package: Package) -> Callable[[str], Package]:
    """A loader for the specs a package's modes name (``<opspec:Mode Source="dock.xpdl">``),
    relative to the package's own file, each read once. The engine compiles what it returns
    when the mode is first entered."""
    base = Path(package.source).parent if package.source else Path.cwd()
    cache: dict[str, Package] = {}

    def load(source: str) -> Package:
        if source not in cache:
            cache[source] = open_spec(base / source)
        return cache[source]

    return load
