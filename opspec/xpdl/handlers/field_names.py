"""References to a data field by its *Name* (TIBCO Business Studio, some Bizagi exports).

XPDL expressions name data fields and formal parameters by Id; TIBCO generates ids
(``_uKBcz3FdEeG8vrjgicxFKw``) and writes conditions, actual parameters and assignments with
the field's Name (``Field > 3``), which its own engine resolves. After a package is built,
:func:`resolve_field_names` rewrites, in every process, each name that is no Id in scope but is
the Name of exactly one field in scope (the process's formal parameters and data fields, then
the package's data fields: a process-level declaration hides a package-level one) into that
field's Id, with one ``field-by-name`` warning per process and name, at its first use. A name
that is an Id in scope always means that Id; a Name two fields share resolves to none of them
(``undefined-data-field`` then says which fields carry it). Applications (their scripts see
only their formal parameters) are left as written.
"""

from __future__ import annotations

import dataclasses
import re
from typing import Any

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model import Package
from opspec.model.data import Assignment
from opspec.model.expressions import Name
from opspec.model.process import WorkflowProcess
from opspec.model.resources import Application

__all__ = ["resolve_field_names"]

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def _aliases(package: Package, process: WorkflowProcess) -> dict[str, str]:
    """Name -> Id for the fields of ``process`` (then of the package) that are read by Name."""
    local = [*process.formal_parameters, *process.data_fields]
    ids = {f.id for f in local} | {f.id for f in package.data_fields}
    out: dict[str, str] = {}
    ambiguous: set[str] = set()
    for scope in (local, package.data_fields):
        seen: dict[str, str] = {}
        for field in scope:
            name = (field.name or "").strip()
            if not name or name == field.id or name in ids or not _IDENT.match(name):
                continue
            if name in seen and seen[name] != field.id:
                ambiguous.add(name)
            seen.setdefault(name, field.id)
        for name, target in seen.items():
            out.setdefault(name, target)   # the process's own fields win
    return {name: target for name, target in out.items() if name not in ambiguous}


class _Rewriter:
    def __init__(self, aliases: dict[str, str], process: WorkflowProcess,
                 fallback: SourceLocation, diagnostics: list[Diagnostic]) -> None:
        self.aliases = aliases
        self.process = process
        self.fallback = fallback
        self.diagnostics = diagnostics
        self.warned: set[str] = set()

    def _resolve(self, name: str, where: SourceLocation | None) -> str:
        target = self.aliases[name]
        if name not in self.warned:
            self.warned.add(name)
            self.diagnostics.append(Diagnostic(
                where or self.fallback, Severity.WARNING, "field-by-name",
                f"{name!r} is the Name of data field {target!r} of process "
                f"{self.process.id!r}, not an Id: read as {target!r} (TIBCO writes field Names; "
                "XPDL expressions use Ids)",
                f"write {target!r} (or give the field the Id {name!r})"))
        return target

    def walk(self, node: Any, where: SourceLocation | None) -> Any:
        if isinstance(node, Name):
            if node.path and node.path[0] in self.aliases:
                return Name((self._resolve(node.path[0], where), *node.path[1:]))
            return node
        if isinstance(node, tuple):
            items = tuple(self.walk(item, where) for item in node)
            return node if all(a is b for a, b in zip(items, node, strict=True)) else items
        if isinstance(node, Application) or not dataclasses.is_dataclass(node) or isinstance(
                node, type):
            return node
        here = getattr(node, "location", None)
        if isinstance(here, SourceLocation):
            where = here
        changes: dict[str, Any] = {}
        for field in dataclasses.fields(node):
            if not field.init or field.name == "location":
                continue
            value = getattr(node, field.name)
            if isinstance(value, (str, int, float, bool)) or value is None:
                continue
            new = self.walk(value, where)
            if new is not value:
                changes[field.name] = new
        if isinstance(node, Assignment):
            root, dot, rest = node.target.partition(".")
            if root in self.aliases:
                changes["target"] = self._resolve(root, where) + dot + rest
        return dataclasses.replace(node, **changes) if changes else node


def resolve_field_names(package: Package, diagnostics: list[Diagnostic]) -> Package:
    """``package`` with field Names used as Ids rewritten to the Ids (warnings appended to
    ``diagnostics``); the same object when nothing is read by Name."""
    fallback = SourceLocation(package.source or f"<package {package.id}>")
    processes = []
    changed = False
    for process in package.processes:
        aliases = _aliases(package, process)
        if aliases:
            new = _Rewriter(aliases, process, process.location or fallback, diagnostics).walk(
                process, process.location)
            changed = changed or new is not process
            processes.append(new)
        else:
            processes.append(process)
    return dataclasses.replace(package, processes=tuple(processes)) if changed else package
