"""Call activities into processes of other BPMN files.

A modeller splits a big model into files: a ``callActivity calledElement="check_stock"`` of
``order.bpmn`` calls the process ``check_stock`` drawn in ``stock.bpmn``. opspec finds that
process as XPDL's ExternalPackage finds a package, and within the same confinement:

1. in a file a ``bpmn:import`` of the diagram names (``location``, relative to the diagram;
   ``calledElement`` may carry the import's prefix, ``tns:check_stock``);
2. else in a BPMN file beside the diagram (``*.bpmn``, ``*.bpmn20.xml``, ``*.xml``; the first
   200 by name) that holds a process of that id.

Every file is read with the hardened reader (size limit, no DOCTYPE, no network, no pipes) and
only inside the diagram's folder tree or a folder of ``OPSPEC_EXTERNAL_PATH``; an import
leading elsewhere is an ``external-package-outside`` error at its line, a URL is never
fetched. The called process — with the processes it calls in its own file, and that file's
participants, pools and package data fields it needs — is built by the same BPMN reader and
joins the diagram's model, so the engine runs it as a process of the file; its diagnostics
keep their own file and line. Files that call each other in a cycle are read once each: the
call that would read a file again is not followed (the target stays undefined, an error at
the call activity's line).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final

from lxml import etree

from opspec.errors import Severity
from opspec.files import allowed_roots, outside_roots
from opspec.model.activities import SubFlow
from opspec.model.data import DataField
from opspec.model.package import Package
from opspec.model.process import WorkflowProcess
from opspec.model.resources import Participant, Pool
from opspec.xpdl.bpmn.common import BPMN, Defs, kids, local, tag

__all__ = ["Imported", "processes_elsewhere"]

_SIBLING_LIMIT: Final = 200
_SUFFIXES: Final = (".bpmn", ".bpmn20.xml", ".xml")
# the files being read, innermost last: a file is never read again while it is being read
_READING: ContextVar[tuple[Path, ...]] = ContextVar("opspec_bpmn_reading", default=())
# the process ids of each file looked into while one diagram is read: every file is parsed at
# most once to be searched, however many calls and files look for processes
_SEEN: ContextVar[dict[Path, frozenset[str]] | None] = ContextVar("opspec_bpmn_seen",
                                                                  default=None)


@dataclass(slots=True)
class Imported:
    """What other files give the diagram: processes, and the participants, pools and package
    data fields they need; ``aliases`` maps a prefixed ``calledElement`` to the process id."""

    processes: list[WorkflowProcess] = field(default_factory=list)
    participants: list[Participant] = field(default_factory=list)
    pools: list[Pool] = field(default_factory=list)
    data_fields: list[DataField] = field(default_factory=list)
    aliases: dict[str, str] = field(default_factory=dict)


def _key(path: Path) -> Path:
    try:
        return path.resolve()
    except (OSError, RuntimeError):
        return path.absolute()


def processes_elsewhere(root: etree._Element, defs: Defs) -> Imported:
    """The processes that call activities of the diagram name but the diagram does not hold,
    read from the files that hold them; ``defs.process_io`` learns their inputs and outputs
    (a call passes them by name, as for a process of the file)."""
    out = Imported()
    local_ids = {p.get("id") for p in kids(root, "process")}
    wanted: dict[str, etree._Element] = {}
    for call in root.iter(tag("callActivity")):
        called = (call.get("calledElement") or "").strip()
        if called and called not in local_ids:
            wanted.setdefault(called, call)
    here = Path(defs.ctx.path)
    if not wanted or not here.is_file():
        return out
    roots = allowed_roots(here)
    reading = _READING.get()
    token = _READING.set((*reading, _key(here)))
    seen_token = _SEEN.set({}) if _SEEN.get() is None else None
    try:
        imports = _imports(root, here, roots, defs)
        taken: dict[str, WorkflowProcess] = {}
        for called, call in wanted.items():
            # a QName (tns:check_stock) names the process of an imported file by its id
            names = [called, called.rsplit(":", 1)[1]] if ":" in called else [called]
            for process_id in names:
                if process_id not in local_ids and process_id not in taken:
                    package = _find(process_id, imports, here, roots, defs, call)
                    if package is not None:
                        _take(package, process_id, local_ids, taken, out, defs, call)
                if process_id in local_ids or process_id in taken:
                    if process_id != called:
                        out.aliases[called] = process_id
                    break
    finally:
        _READING.reset(token)
        if seen_token is not None:
            _SEEN.reset(seen_token)
    for process in out.processes:
        defs.process_io[process.id] = [(f.id, f.mode) for f in process.formal_parameters]
    return out


def _imports(root: etree._Element, here: Path, roots: tuple[Path, ...], defs: Defs
             ) -> list[Path]:
    """The BPMN files the diagram's ``bpmn:import`` elements name, confined."""
    found: list[Path] = []
    for element in kids(root, "import"):
        location = (element.get("location") or "").strip()
        kind = (element.get("importType") or BPMN).strip()
        if not location or kind != BPMN:
            continue
        if "://" in location:
            defs.ctx.warning(element, "remote-external-package",
                             f"bpmn:import {location!r} is a URL; opspec never fetches remote "
                             "files", "download it and import it by a relative path")
            continue
        target = here.parent / location
        outside = outside_roots(target, roots)
        if outside is not None:
            defs.ctx.error(element, "external-package-outside",
                           f"bpmn:import {location!r} leads outside the diagram's folder "
                           f"({outside}); opspec reads imported files only inside "
                           f"{' or '.join(str(r) for r in roots)}",
                           "copy the file into the diagram's folder, or allow its folder "
                           "with OPSPEC_EXTERNAL_PATH (docs/validation.md)")
            continue
        if not target.is_file():
            defs.ctx.error(element, "missing-external-package",
                           f"bpmn:import {location!r} names no file ({target})",
                           "fix the location (it is relative to this file) or add the file")
            continue
        found.append(target)
    return found


def _siblings(here: Path, roots: tuple[Path, ...], skip: list[Path]) -> Iterator[Path]:
    try:
        names = sorted(p for p in here.parent.iterdir()
                       if p.name.lower().endswith(_SUFFIXES))
    except OSError:
        return
    skipped = {_key(p) for p in (here, *skip)}
    for candidate in names[:_SIBLING_LIMIT]:
        if _key(candidate) in skipped or outside_roots(candidate, roots) is not None:
            continue
        if candidate.is_file():
            yield candidate


def _find(process_id: str, imports: list[Path], here: Path, roots: tuple[Path, ...],
          defs: Defs, call: etree._Element) -> Package | None:
    """The package of the first imported, else sibling, BPMN file holding ``process_id``."""
    seen = _SEEN.get()
    for candidate in (*imports, *_siblings(here, roots, imports)):
        key = _key(candidate)
        if key in _READING.get():
            continue                      # being read: a cycle of files, not followed
        if seen is not None and key in seen and process_id not in seen[key]:
            continue
        root = _parse(candidate)
        ids = frozenset(p.get("id") or "" for p in root.iterchildren(tag("process"))) \
            if root is not None else frozenset()
        if seen is not None:
            seen[key] = ids
        if root is None or process_id not in ids:
            continue
        return _build(candidate, root, defs, call, process_id)
    return None


def _parse(path: Path) -> etree._Element | None:
    """The ``definitions`` root of a BPMN file, read with every protection; ``None`` for
    anything else (an XPDL file, a broken file: not what is looked for)."""
    from opspec.xpdl.bpmn import is_bpmn
    from opspec.xpdl.reader import XmlReadError, parse_safely, read_file

    try:
        parsed = parse_safely(read_file(path), path=str(path))
    except XmlReadError:
        return None
    return parsed.root if is_bpmn(parsed.root) else None


def _build(path: Path, root: etree._Element, defs: Defs, call: etree._Element,
           process_id: str) -> Package | None:
    from opspec.xpdl.bpmn.package import build_definitions
    from opspec.xpdl.handlers.common import BuildContext

    ctx = BuildContext(path=str(path), version=defs.ctx.version)
    try:
        package = build_definitions(root, ctx)
    except (MemoryError, KeyboardInterrupt):
        raise
    except Exception as error:  # noqa: BLE001 - a user never sees a traceback
        defs.ctx.error(call, "internal-error", f"opspec could not read {path.name}, which "
                       f"holds process {process_id!r} ({type(error).__name__}: {error})",
                       "this is a bug in opspec; please report it with the files")
        return None
    defs.ctx.diagnostics.extend(d for d in ctx.diagnostics if d.severity is not Severity.INFO)
    defs.info(call, "called-elsewhere",
              f"{local(call)} {call.get('id')!r} calls process {process_id!r} of {path.name}",
              "")
    return package


def _take(package: Package, process_id: str, local_ids: set[str | None],
          taken: dict[str, WorkflowProcess], out: Imported, defs: Defs,
          call: etree._Element) -> None:
    """``process_id`` of ``package`` and the processes it calls there, into ``out``."""
    by_id = {p.id: p for p in package.processes}
    stack = [process_id]
    while stack:
        current = by_id.get(stack.pop())
        if current is None or current.id in taken:
            continue
        if current.id in local_ids:
            defs.ctx.error(call, "duplicate-id",
                           f"process {current.id!r} of {Path(package.source or '?').name}, "
                           f"which {process_id!r} calls, has the id of a process of this file",
                           "give the processes of the two files different ids")
            continue
        taken[current.id] = current
        out.processes.append(current)
        stack.extend(a.body.process for a in current.all_activities()
                     if isinstance(a.body, SubFlow))
    have = {p.id for p in out.participants}
    for participant in package.participants:
        if participant.id not in have:
            out.participants.append(participant)
            have.add(participant.id)
    out.pools.extend(p for p in package.pools if p.process in taken and p not in out.pools)
    fields = {f.id for f in out.data_fields}
    out.data_fields.extend(f for f in package.data_fields if f.id not in fields)
