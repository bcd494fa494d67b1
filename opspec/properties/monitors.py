"""Monitors: the properties a spec declares (``opspec:Monitor``), watched while a run happens.

A monitor is a :class:`~opspec.properties.language.Property` ("no dispense within 4 h of the
previous one") watched online: :meth:`Monitor.start` gives a fresh :class:`MonitorRun` for one
run, a trace listener with a ``selects`` attribute (so the engine builds only the events the
monitor needs) that records each :class:`Violation` with its time and its witness. The
language, the classes and the evaluator are :mod:`opspec.properties.language`, shared with the
trace predicates and scenario ``then`` lines that judge stored traces: the same text gives the
same verdict and witness online and offline. This module reads the spec's declarations.

The text form (the value of a package ``ExtendedAttribute Name="opspec:Monitor"``, one
monitor per line, ``#`` starts a comment) is read by :func:`parse_monitor`::

    min_gap dispense 4h                              no two occurrences closer than 4 h
    never notify_caregiver                           it never happens
    never_while dispense after record_missed until sound_alarm
    max_count dispense 4 per 24h                     at most 4 in any 24 h window
    bounded_response sound_alarm dispense|record_missed 15 min

and every other form of the property language (``eventually A``, ``count A <= 4``,
``response A B``, ``A before B``, ``B within 15 min after A``...).

Over many runs, violations become a hazard: :func:`opspec.statistics.poisson_interval` gives
the exact (Garwood) interval of a rate of events per unit of exposure (e.g. per user-day).

Pure Python, no wall clock: importable by any layer above the property language.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from opspec.errors import ConfigurationError, SourceLocation
from opspec.properties.language import Property
from opspec.properties.text_form import parse_property

__all__ = ["MONITOR_ATTRIBUTE", "Monitor", "declared_monitors", "package_monitors",
           "parse_monitor"]

#: the package ExtendedAttribute holding monitors in their text form
MONITOR_ATTRIBUTE = "opspec:Monitor"

#: a monitor is a property watched while the run happens (the same class)
Monitor = Property


def parse_monitor(text: str, *, location: SourceLocation | None = None) -> Monitor:
    """A monitor from its text form; :class:`ConfigurationError` at ``location`` when the
    text cannot be read (listing the forms)."""
    return parse_property(text, what="monitor", location=location)


def package_monitors(attributes: Iterable[object], *, path: str | None = None
                     ) -> list[Monitor]:
    """The monitors declared by ``ExtendedAttribute Name="opspec:Monitor"`` in
    ``attributes`` (a package's ``extended_attributes``): the ``Value``, or the text with one
    monitor per line (``#`` comments)."""
    out = []
    for attribute in attributes:
        if getattr(attribute, "name", None) != MONITOR_ATTRIBUTE:
            continue
        location = getattr(attribute, "location", None) or (
            SourceLocation(path) if path else None)
        body = "\n".join(x for x in (getattr(attribute, "value", None),
                                     getattr(attribute, "text", None)) if x)
        for line in body.splitlines():
            line = line.split("#", 1)[0].strip()
            if line:
                out.append(parse_monitor(line, location=location))
    return out


def declared_monitors(compiled: Any) -> list[Monitor]:
    """The monitors ``compiled`` (a :class:`~opspec.engine.compiled.CompiledPackage`) declares
    as ``opspec:Monitor``, bound to its names: :class:`ConfigurationError` at the attribute's
    ``file:line`` when one cannot be read or names something the spec does not have."""
    from opspec.engine.names import spec_names

    package = compiled.package
    names = spec_names(compiled)
    out = []
    for attribute in getattr(package, "extended_attributes", ()):
        if getattr(attribute, "name", None) != MONITOR_ATTRIBUTE:
            continue
        location = getattr(attribute, "location", None)
        for monitor in package_monitors((attribute,), path=getattr(package, "source", None)):
            try:
                out.append(monitor.bind(names))
            except ConfigurationError as error:
                raise ConfigurationError(f"monitor {monitor.text!r}: {error.message}",
                                         location=location or error.location,
                                         hint=error.hint) from None
    return out
