"""Which process level of a spec each of its errors lies in, for ``opspec check``.

A spec with errors is still explored, but a level whose own lines hold an error (a dangling
transition, a condition opspec cannot read) must not be called sound: what was explored is
only what could be read of it. An error lies in a level when its line falls between the
level's first line and its last known one: a process runs up to the next process of the same
file (its closing tag and extended attributes included), the last one up to the last line of
its elements; an activity set from its own line to the last line of its activities and
transitions, and an error there lies in the set's level, not its process's. Errors of the
package (its participants, pools, modes), of another file or without a line lie in no level.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    from opspec.errors import Diagnostic

__all__ = ["errors_by_level"]


def _lines(elements: Iterable[Any]) -> list[int]:
    return [e.location.line for e in elements
            if e.location is not None and e.location.line is not None]


def _spans(package: Any) -> list[tuple[str, str, int, int]]:
    """(level, path, first line, last line) of every located level, activity sets first so
    that an error inside a set is given to the set."""
    located = [p for p in package.processes
               if p.location is not None and p.location.line is not None]
    spans: list[tuple[str, str, int, int]] = []
    for process in located:
        path, first = process.location.path, process.location.line
        later = [p.location.line for p in located
                 if p.location.path == path and p.location.line > first]
        own = _lines((*process.data_fields, *process.formal_parameters,
                      *process.participants, *process.applications, *process.activities,
                      *process.transitions))
        sets = []
        for activity_set in process.activity_sets:
            lines = _lines((activity_set, *activity_set.activities, *activity_set.transitions))
            if lines:
                sets.append((f"{process.id}/{activity_set.id}", path, min(lines), max(lines)))
        last = min(later) - 1 if later else max([first, *own, *(s[3] for s in sets)])
        spans.extend(sets)
        spans.append((process.id, path, first, last))
    return spans


def errors_by_level(package: Any, errors: Sequence[Diagnostic]) -> dict[str, list[Diagnostic]]:
    """The errors lying in each level (levels without any are left out)."""
    spans = _spans(package)
    found: dict[str, list[Diagnostic]] = {}
    for error in errors:
        line = error.location.line
        if line is None:
            continue
        for level, path, first, last in spans:
            if error.location.path == path and first <= line <= last:
                found.setdefault(level, []).append(error)
                break
    return found
