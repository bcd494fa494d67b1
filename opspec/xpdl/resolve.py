"""Resolving references across files: ExternalPackages and SubFlows into other packages.

Contract:

- an ``ExternalPackage`` ``href`` is a path relative to the file that declares it; when no such
  file exists, a package with the referenced Id is looked for among the files beside it (exports
  often rename files); URLs are never fetched;
- a SubFlow ``PackageRef`` names a package by Id (among loaded packages or the ExternalPackage
  Ids of the calling package) or by relative href;
- reference cycles are reported (``package-cycle``, ``subflow-cycle``) naming the cycle, never
  followed forever: every file is loaded at most once and graph walks are iterative;
- a missing file is an error at the file:line of the reference;
- files are read only inside the folder tree of the root spec (the folder of the file given to
  opspec, and every folder below it) and the folders listed in the environment variable
  :data:`EXTERNAL_PATH_VARIABLE`; an href that leads elsewhere (``/etc/passwd``,
  ``../../secrets.xpdl``, a link pointing out of the tree) is refused with
  ``external-package-outside`` before the file is even looked at.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.files import EXTERNAL_PATH_VARIABLE, allowed_roots, outside_message, outside_roots
from opspec.model.activities import Execution, GatewayType, SubFlow
from opspec.model.package import ExternalPackage, Package
from opspec.model.process import ConditionKind, Transition, WorkflowProcess

__all__ = ["EXTERNAL_PATH_VARIABLE", "Loader", "Resolution", "allowed_roots", "outside_roots",
           "resolve"]

#: Loads one file: ``(package or None, diagnostics)``; never raises.
Loader = Callable[[Path], tuple[Package | None, list[Diagnostic]]]

_SIBLING_SCAN_LIMIT = 200
_SUFFIXES = (".xpdl", ".xml", ".frg")


@dataclass(slots=True)
class Resolution:
    """Everything loaded while resolving one root package."""

    packages: dict[str, Package] = field(default_factory=dict)
    paths: dict[Path, str] = field(default_factory=dict)     # file -> package id
    diagnostics: list[Diagnostic] = field(default_factory=list)
    roots: tuple[Path, ...] = ()                              # where files may be read
    refused: set[str] = field(default_factory=set)            # PackageRefs outside the roots

    def error(self, location: SourceLocation | None, code: str, message: str, hint: str,
              severity: Severity = Severity.ERROR) -> None:
        self.diagnostics.append(Diagnostic(location or SourceLocation("<unknown>"), severity,
                                           code, message, hint))


def _key(path: Path) -> Path:
    try:
        return path.resolve()
    except (OSError, RuntimeError):
        return path.absolute()


def _outside_message(reference: str, where: str, roots: Sequence[Path]) -> tuple[str, str]:
    return outside_message(reference, where, roots, files="referenced packages",
                           thing="the package")


def _package_id_of(path: Path) -> str | None:
    """The Id of the Package root of ``path``, reading only its first start tag."""
    try:
        if path.stat().st_size == 0:
            return None
        for _, element in etree.iterparse(str(path), events=("start",), resolve_entities=False,
                                          no_network=True, load_dtd=False, huge_tree=False):
            value = element.get("Id")
            return str(value) if value is not None else None
    except (OSError, etree.LxmlError):
        return None
    return None


def _sibling_with_id(base: Path, package_id: str, roots: Sequence[Path] = ()
                     ) -> Path | None:
    """A file beside ``base`` (not ``base`` itself, nor a link leading out of ``roots``) whose
    package has Id ``package_id``."""
    try:
        candidates = sorted(p for p in base.parent.iterdir() if p.suffix.lower() in _SUFFIXES)
    except OSError:
        return None
    for candidate in candidates[:_SIBLING_SCAN_LIMIT]:
        if _key(candidate) == _key(base):
            continue
        if roots and outside_roots(candidate, roots) is not None:
            continue
        if candidate.is_file() and _package_id_of(candidate) == package_id:
            return candidate
    return None


def _external_target(ext: ExternalPackage, base: Path, roots: Sequence[Path] = ()
                     ) -> Path | None:
    href = ext.href.strip()
    if "://" in href:
        return None
    if href:
        target = base.parent / href
        if target.is_file():
            return target
    for wanted in (ext.id, Path(href).stem if href else ""):
        if wanted:
            found = _sibling_with_id(base, wanted, roots)
            if found is not None:
                return found
    return None


def _load_externals(root: Package, root_path: Path, load: Loader, res: Resolution) -> None:
    # Iterative depth-first walk; ``trail`` is the chain of files from the root (for cycles).
    stack: list[tuple[Package, Path, tuple[Path, ...]]] = [(root, _key(root_path), (_key(root_path),))]
    while stack:
        package, path, trail = stack.pop()
        for ext in package.external_packages:
            if "://" in ext.href:
                res.error(ext.location, "remote-external-package",
                          f"ExternalPackage {ext.href!r} is a URL; opspec never fetches remote files",
                          "download it and refer to it by a relative path", Severity.WARNING)
                continue
            href = ext.href.strip()
            outside = outside_roots(path.parent / href, res.roots) if href else None
            if outside is not None:
                message, hint = _outside_message(f"ExternalPackage {href!r}", outside,
                                                 res.roots)
                res.error(ext.location, "external-package-outside", message, hint)
                continue
            target = _external_target(ext, path, res.roots)
            if target is None:
                res.error(ext.location, "missing-external-package",
                          f"ExternalPackage {ext.href or ext.id!r} not found (looked for "
                          f"{(path.parent / ext.href) if ext.href else ext.id} and for a package "
                          f"with Id {ext.id!r} beside it)",
                          "fix the href (it is relative to this file) or add the file")
                continue
            key = _key(target)
            if key in trail:
                cycle = " -> ".join(p.name for p in (*trail[trail.index(key):], key))
                res.error(ext.location, "package-cycle",
                          f"external packages refer to each other in a cycle: {cycle}",
                          "remove one of the ExternalPackage references")
                continue
            if key in res.paths:
                continue
            loaded, diagnostics = load(target)
            res.diagnostics.extend(diagnostics)
            res.paths[key] = loaded.id if loaded is not None else ""
            if loaded is None:
                continue
            _register(loaded, res)
            stack.append((loaded, key, (*trail, key)))


def _register(package: Package, res: Resolution) -> None:
    if package.id in res.packages:
        other = res.packages[package.id]
        res.error(package.location, "duplicate-package-id",
                  f"package Id {package.id!r} is also used by {other.source}; this one is ignored",
                  "give every package its own Id", Severity.WARNING)
        return
    res.packages[package.id] = package


def _subflows(process: WorkflowProcess
              ) -> Iterator[tuple[SubFlow, SourceLocation | None, bool]]:
    """Each SubFlow call of ``process``, and whether it *certainly* runs whenever the process
    does (see :func:`_certain_activities`)."""
    certain: set[str] | None = None       # worked out at the first SubFlow (most have none)
    for activity in process.all_activities():
        if isinstance(activity.body, SubFlow):
            if certain is None:
                certain = _certain_activities(process)
            yield activity.body, activity.location, activity.id in certain


def _certain_activities(process: WorkflowProcess) -> set[str]:
    """Top-level activities that run in every execution of ``process``: reachable from a
    start through transitions that are always taken (unconditional ones out of activities
    whose outgoing transitions are all unconditional, with no split or an AND split), into
    activities without an AND/OR/complex join. A recursive call outside this set may be
    avoided by a condition (a base case), so the recursion can end."""
    activities = {a.id: a for a in process.activities}
    outgoing: dict[str, list[Transition]] = {}
    incoming: set[str] = set()
    for transition in process.transitions:
        outgoing.setdefault(transition.source, []).append(transition)
        incoming.add(transition.target)
    stack = [a for a in activities if a not in incoming]
    certain: set[str] = set()
    while stack:
        current = stack.pop()
        if current in certain or current not in activities:
            continue
        certain.add(current)
        activity = activities[current]
        normal = [t for t in outgoing.get(current, ())
                  if t.condition.kind not in (ConditionKind.EXCEPTION,
                                              ConditionKind.DEFAULTEXCEPTION)]
        if activity.split is not None and activity.split.type is not GatewayType.AND and (
                len(normal) > 1):
            continue
        if any(t.condition.kind is not ConditionKind.NONE for t in normal):
            continue
        for transition in normal:
            target = activities.get(transition.target)
            if target is not None and (target.join is None or target.join.type in (
                    GatewayType.XOR, GatewayType.EVENT)):
                stack.append(target.id)
    return certain


def _package_by_ref(ref: str, caller: Package, res: Resolution, load: Loader) -> Package | None:
    if ref in res.packages:
        return res.packages[ref]
    for ext in caller.external_packages:
        if ref in (ext.id, ext.name, ext.href):
            package_id = res.paths.get(_key(Path(caller.source or ".").parent / ext.href))
            if package_id and package_id in res.packages:
                return res.packages[package_id]
    if caller.source and "://" not in ref:
        target = Path(caller.source).parent / ref
        outside = outside_roots(target, res.roots) if res.roots else None
        if outside is not None:
            res.refused.add(ref)
            return None
        if outside is None and target.is_file():
            key = _key(target)
            if key not in res.paths:
                loaded, diagnostics = load(target)
                res.diagnostics.extend(diagnostics)
                res.paths[key] = loaded.id if loaded is not None else ""
                if loaded is not None:
                    _register(loaded, res)
            return res.packages.get(res.paths[key])
    return None


Node = tuple[str, str]   # (package id, process id)
Edge = tuple[Node, Execution, SourceLocation | None, bool]   # ..., the call always runs


def _call_graph(res: Resolution, load: Loader) -> dict[Node, list[Edge]]:
    graph: dict[Node, list[Edge]] = {}
    for package in list(res.packages.values()):
        for process in package.processes:
            edges = graph.setdefault((package.id, process.id), [])
            for subflow, location, certain in _subflows(process):
                target = _target(subflow, package, res, load, location)
                if target is not None:
                    edges.append((target, subflow.execution, location, certain))
    return graph


def _target(subflow: SubFlow, caller: Package, res: Resolution, load: Loader,
            location: SourceLocation | None) -> Node | None:
    if subflow.package_ref:
        package = _package_by_ref(subflow.package_ref, caller, res, load)
        if package is None and subflow.package_ref in res.refused:
            message, hint = _outside_message(
                f"SubFlow PackageRef {subflow.package_ref!r}",
                str(Path(caller.source or ".").parent / subflow.package_ref), res.roots)
            res.error(location, "external-package-outside", message, hint)
            return None
        if package is None:
            res.error(location, "unresolved-subflow",
                      f"SubFlow names package {subflow.package_ref!r}, which is not loaded",
                      "declare it as an ExternalPackage or fix PackageRef")
            return None
        if package.process(subflow.process) is None:
            res.error(location, "unresolved-subflow",
                      f"SubFlow calls process {subflow.process!r}, which is not in package "
                      f"{package.id!r}", "fix the SubFlow Id")
            return None
        return (package.id, subflow.process)
    if caller.process(subflow.process) is not None:
        return (caller.id, subflow.process)
    for package in res.packages.values():
        if package.process(subflow.process) is not None:
            return (package.id, subflow.process)
    if caller.external_packages:
        # Without external packages, checks.py reports the undefined target in its own package.
        res.error(location, "unresolved-subflow",
                  f"SubFlow calls process {subflow.process!r}, found neither in package "
                  f"{caller.id!r} nor in its external packages", "fix the SubFlow Id")
    return None


def _report_cycles(graph: dict[Node, list[Edge]], res: Resolution) -> None:
    """Every elementary cycle found by an iterative DFS, each reported once."""
    state: dict[Node, int] = {}          # 1 = on the stack, 2 = done
    seen_cycles: set[frozenset[Node]] = set()
    for start in graph:
        if state.get(start):
            continue
        path: list[Node] = [start]
        edges_on_path: list[Edge] = []
        iterators = [iter(graph.get(start, []))]
        state[start] = 1
        while iterators:
            edge = next(iterators[-1], None)
            if edge is None:
                iterators.pop()
                state[path.pop()] = 2
                if edges_on_path:
                    edges_on_path.pop()
                continue
            target = edge[0]
            if state.get(target) == 1:
                index = path.index(target)
                members = frozenset(path[index:])
                if members not in seen_cycles:
                    seen_cycles.add(members)
                    loop_edges = [*edges_on_path[index:], edge]
                    sync = all(e[1] is Execution.SYNCHR for e in loop_edges)
                    if sync and not all(e[3] for e in loop_edges):
                        # some call of the cycle depends on a condition: a base case can end
                        # the recursion (the engine limits its depth at run time)
                        continue
                    names = " -> ".join(f"{p}:{q}" for p, q in (*path[index:], target))
                    res.error(edge[2], "subflow-cycle",
                              f"subflows call each other in a cycle: {names}",
                              "synchronous calls in a cycle never finish; break the cycle"
                              if sync else "asynchronous starts in a cycle spawn instances "
                              "without end unless a condition stops them",
                              Severity.ERROR if sync else Severity.WARNING)
            elif not state.get(target):
                state[target] = 1
                path.append(target)
                edges_on_path.append(edge)
                iterators.append(iter(graph.get(target, [])))


def resolve(root: Package, root_path: Path, load: Loader) -> Resolution:
    """Load every package ``root`` refers to, resolve SubFlows and report cycles."""
    res = Resolution(roots=allowed_roots(root_path))
    res.packages[root.id] = root
    res.paths[_key(root_path)] = root.id
    _load_externals(root, root_path, load, res)
    _report_cycles(_call_graph(res, load), res)
    return res
