"""What keeps a package from being valid *standard* XPDL 2.1 once written out.

opspec reads packages the official XPDL 2.1 schema rejects (every tool writes some), and the
writer keeps them as they are. ``opspec preprocess`` promises standard XPDL 2.1, so it warns
(code ``not-schema-valid``) instead of silently writing a file that schema validation would
refuse. The schema's identity constraints that real files break (bpmnxpdl_31.xsd, element
``Package``):

- ``ActivityIds.Package``: activity ids are unique in the whole package (opspec scopes them
  per process and activity set, as XPDL 1.0 and most tools do);
- ``ProcessIds.Package``: processes and activity sets share one id space;
- ``SubFlowIdRef.Package``: a SubFlow names a process of the same package (not of an
  external package).

One warning per kind of problem, naming the first offenders, keeps the output short for
packages that break a rule hundreds of times.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model.activities import SubFlow
from opspec.model.package import Package

__all__ = ["schema_warnings"]

_SHOWN = 3


def _names(ids: Iterable[str]) -> str:
    listed = list(ids)
    shown = ", ".join(repr(i) for i in listed[:_SHOWN])
    more = len(listed) - _SHOWN
    return shown + (f" and {more} more" if more > 0 else "")


def schema_warnings(package: Package) -> tuple[Diagnostic, ...]:
    """Warnings for each rule of the XPDL 2.1 schema the written ``package`` would break."""
    file = SourceLocation(package.source or "<package>",
                          package.location.line if package.location is not None else None)
    out: list[Diagnostic] = []

    def warn(message: str, hint: str, where: SourceLocation | None = None) -> None:
        out.append(Diagnostic(where or file, Severity.WARNING, "not-schema-valid",
                              f"the output will not be valid XPDL 2.1: {message}", hint))

    activities = [a for p in package.processes for a in p.all_activities()]
    activity_ids = Counter(a.id for a in activities)
    repeated = [i for i, n in activity_ids.items() if n > 1]
    if repeated:
        # at the second activity carrying the first repeated id
        second = [a for a in activities if a.id == repeated[0]][1]
        warn(f"activity id{'s' * (len(repeated) > 1)} {_names(repeated)} "
             f"{'are' if len(repeated) > 1 else 'is'} used more than once in the package "
             "(the 2.1 schema wants activity ids unique package-wide)",
             "give activities ids unique in the package if the output must pass the schema",
             second.location)
    process_ids = Counter([p.id for p in package.processes]
                          + [s.id for p in package.processes for s in p.activity_sets])
    shared = [i for i, n in process_ids.items() if n > 1]
    if shared:
        warn(f"process and activity-set id{'s' * (len(shared) > 1)} {_names(shared)} "
             "repeat (the 2.1 schema gives processes and activity sets one id space)",
             "rename the repeated activity sets or processes")
    local = {p.id for p in package.processes}
    calls = [a for a in activities
             if isinstance(a.body, SubFlow) and a.body.process not in local]
    external = list(dict.fromkeys(a.body.process for a in calls if isinstance(a.body, SubFlow)))
    if external:
        warn(f"SubFlow{'s' * (len(external) > 1)} call{'s' * (len(external) == 1)} "
             f"{_names(external)}, not a process of this package (the 2.1 schema wants "
             "SubFlow targets in the same package)",
             "copy the called processes into this package if the output must pass the schema",
             calls[0].location)
    return tuple(out)
