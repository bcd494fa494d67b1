"""Moving a spec to another folder: relative paths to companion files follow it.

A spec names files relative to its own folder: ``opspec:WorldFile`` (the world's parameters),
``<opspec:Mode Source="…">`` (specs loaded at a mode change) and ``ExternalPackage href``s.
``opspec preprocess IN -o OUT`` writes ``OUT`` elsewhere, so :func:`relocate` rewrites each
such path to lead from ``OUT``'s folder to the same file (``../specs/vacuum.world.toml``).
URLs and absolute paths are left as they are. A file that then lies outside ``OUT``'s folder
tree would be refused when ``OUT`` is read (:mod:`opspec.xpdl.resolve`, :mod:`opspec.files`):
a world file is copied beside ``OUT`` instead when the caller asks for copies (``opspec
preprocess`` does), and otherwise, like an ExternalPackage or a mode Source, gets a
``relocated-outside`` warning saying how to allow it.
"""

from __future__ import annotations

import dataclasses
import html
import os
import re
from pathlib import Path, PurePosixPath

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.files import EXTERNAL_PATH_VARIABLE, allowed_roots, outside_roots
from opspec.model.common import ExtendedAttribute
from opspec.model.package import Package

__all__ = ["relocate"]

WORLD_FILE = "opspec:WorldFile"
MODES = "opspec:Modes"
_SOURCE = re.compile(r"""(\bSource\s*=\s*")([^"]*)(")""")


def _moved(value: str | None, source_dir: Path, output_dir: Path) -> str | None:
    """``value`` rewritten to lead from ``output_dir`` to what it named from ``source_dir``
    (``None`` when it needs no rewrite)."""
    if not value or "://" in value or Path(value).is_absolute():
        return None
    target = os.path.abspath(source_dir / value)
    moved = os.path.relpath(target, os.path.abspath(output_dir))
    moved = PurePosixPath(*Path(moved).parts).as_posix()
    return None if moved == PurePosixPath(value).as_posix() else moved


def relocate(package: Package, source: Path, output: Path, *,
             copies: list[tuple[Path, Path]] | None = None
             ) -> tuple[Package, list[Diagnostic]]:
    """``package`` (read from ``source``) with its relative companion paths rewritten for a
    copy written to ``output``, and warnings for references the copy cannot follow.

    With ``copies``, a world file that would lie outside ``output``'s folder tree is named by
    its file name instead and ``(file, copy beside output)`` is appended for the caller to
    copy; without, it gets the ``relocated-outside`` warning."""
    source_dir, output_dir = source.parent, output.parent
    roots = allowed_roots(output)
    diagnostics: list[Diagnostic] = []

    def outside(moved: str, what: str, written: str, location: SourceLocation | None) -> None:
        if outside_roots(output_dir / moved, roots) is not None:
            diagnostics.append(Diagnostic(
                location or SourceLocation(str(source)), Severity.WARNING,
                "relocated-outside",
                f"the output refers to {what} {written!r} as {moved!r}, outside its folder "
                f"{output_dir}: opspec will not read it from there",
                f"write the output beside {source.name}, copy the file next to it, or set "
                f"{EXTERNAL_PATH_VARIABLE}"))

    def mode_source(match: re.Match[str]) -> str:
        moved = _moved(html.unescape(match.group(2)), source_dir, output_dir)
        return match.group(0) if moved is None else (
            f"{match.group(1)}{html.escape(moved, quote=True)}{match.group(3)}")

    def world_file(attribute: ExtendedAttribute) -> ExtendedAttribute:
        moved = _moved(attribute.value, source_dir, output_dir)
        if moved is None or not attribute.value:
            return attribute
        if outside_roots(output_dir / moved, roots) is None:
            return dataclasses.replace(attribute, value=moved)
        if copies is None:
            outside(moved, "the world file", attribute.value, attribute.location)
            return dataclasses.replace(attribute, value=moved)
        name = Path(attribute.value).name
        copies.append((source_dir / attribute.value, output_dir / name))
        return dataclasses.replace(attribute, value=name)

    attributes = tuple(
        world_file(a) if a.name == WORLD_FILE else
        # the opspec:Modes attribute is written back verbatim: its Source attributes too
        dataclasses.replace(a, raw_xml=_SOURCE.sub(mode_source, a.raw_xml))
        if a.name == MODES and a.raw_xml else a
        for a in package.extended_attributes)
    modes = []
    for mode in package.modes:
        moved = _moved(mode.source, source_dir, output_dir)
        if moved is not None and mode.source:
            outside(moved, f"the Source of mode {mode.id!r}", mode.source, mode.location)
        modes.append(dataclasses.replace(mode, source=moved or mode.source))
    externals = []
    for external in package.external_packages:
        moved = _moved(external.href.strip(), source_dir, output_dir)
        if moved is None:
            externals.append(external)
            continue
        externals.append(dataclasses.replace(external, href=moved))
        outside(moved, "ExternalPackage", external.href, external.location)
    relocated = dataclasses.replace(package, extended_attributes=attributes, modes=tuple(modes),
                                    external_packages=tuple(externals))
    return relocated, diagnostics
