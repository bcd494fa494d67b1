"""The metrics ``opspec evaluate`` measures when a spec declares none (no opspec:Metrics): a
diagram from a modeller (a BPSim or QBP scenario with arrivals and task durations, say)
otherwise ran thousands of users and estimated nothing. Per process, what a BPM simulator
reports first: how many of its instances completed, and their cycle time (from an
instance's start to its completion). Each says in its description that it is opspec's
default (:func:`is_default`), which the report and the command's output tell the reader.
"""

from __future__ import annotations

from opspec.model.package import Package
from opspec.model.sisarl import EventSelector, MetricDefinition, MetricKind

__all__ = ["DEFAULT_NOTE", "default_metrics", "is_default"]

#: the end of every default metric's description
DEFAULT_NOTE = "opspec's default (the spec declares no metrics)"


def default_metrics(package: Package) -> tuple[MetricDefinition, ...]:
    """``{process}_completed`` and ``{process}_cycle_time_s`` for every process of
    ``package``, in file order."""
    out: list[MetricDefinition] = []
    for process in package.processes:
        label = repr(process.name or process.id)
        out.append(MetricDefinition(
            name=f"{process.id}_completed", kind=MetricKind.COUNT,
            description=f"instances of process {label} completed; {DEFAULT_NOTE}",
            select=EventSelector(event="process.completed", process=process.id)))
        out.append(MetricDefinition(
            name=f"{process.id}_cycle_time_s", kind=MetricKind.DURATION,
            description=f"cycle time of process {label}: from an instance's start to its "
            f"completion; {DEFAULT_NOTE}",
            start=EventSelector(event="process.started", process=process.id),
            end=EventSelector(event="process.completed", process=process.id), unit="s"))
    return tuple(out)


def is_default(description: str | None) -> bool:
    """Whether a metric with this description is one of :func:`default_metrics`."""
    return (description or "").endswith(DEFAULT_NOTE)
