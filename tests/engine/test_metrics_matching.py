"""A metrics listener finds the selectors an event matches once per distinct (kind, process,
activity) and keeps that answer (issue 31, the engine from source): the counts and durations
must be those of testing every selector at every event, in the declared order, whatever the
order the events first arrive in.

A duration is "seconds from the ``first`` (or ``last``) event matching ``start`` to the next
event matching ``end`` of the same instance" (opspec.engine.metrics); a selector's ``None``
process or activity matches any.
"""

from __future__ import annotations

from opspec.engine.metrics import MetricsListener
from opspec.engine.trace import TraceEvent
from opspec.model import EventSelector, MetricDefinition, MetricKind

STARTED, COMPLETED = "activity.started", "activity.completed"


def _on(event: str, process: str | None = None, activity: str | None = None,
        which: str = "first") -> EventSelector:
    return EventSelector(event=event, process=process, activity=activity, which=which)


def _listener() -> MetricsListener:
    return MetricsListener([
        MetricDefinition(name="any_done", kind=MetricKind.COUNT,
                         select=_on(COMPLETED)),
        MetricDefinition(name="alarms", kind=MetricKind.COUNT,
                         select=_on(COMPLETED, "notify", "alarm")),
        MetricDefinition(name="in_notify", kind=MetricKind.COUNT,
                         select=_on(COMPLETED, "notify")),
        # start and end on the same event kind and activity: the start must be taken
        # before the end at each event (declared order), so every sample is 0 s
        MetricDefinition(name="instant", kind=MetricKind.DURATION,
                         start=_on(COMPLETED, "notify", "alarm"),
                         end=_on(COMPLETED, "notify", "alarm")),
        MetricDefinition(name="latency", kind=MetricKind.DURATION,
                         start=_on(STARTED, "notify", "alarm", which="last"),
                         end=_on(COMPLETED, "notify", "report")),
    ])


def test_counts_and_durations_over_repeated_events() -> None:
    metrics = _listener()
    for instance, t in ((1, 0.0), (2, 100.0)):
        metrics.raw(t, STARTED, "notify", instance, "alarm")
        metrics.raw(t + 5.0, STARTED, "notify", instance, "alarm")     # "last" start wins
        metrics.raw(t + 10.0, COMPLETED, "notify", instance, "alarm")
        metrics.raw(t + 12.0, COMPLETED, "user", instance, "alarm")    # another process
        metrics.raw(t + 30.0, COMPLETED, "notify", instance, "report")
        metrics.raw(t + 31.0, "user.omitted", None, instance, None)    # nobody selects it
    assert metrics.counts == {"any_done": 6, "alarms": 2, "in_notify": 4}
    assert metrics.samples == {"instant": [0.0, 0.0], "latency": [25.0, 25.0]}


def test_a_trace_event_and_its_raw_fields_count_the_same() -> None:
    by_event, by_raw = _listener(), _listener()
    fields = [(1.0, COMPLETED, "notify", 1, "alarm"), (2.0, COMPLETED, "other", 1, "x"),
              (3.0, COMPLETED, "notify", 1, "alarm")]
    for seq, (t, kind, process, instance, activity) in enumerate(fields, 1):
        by_event(TraceEvent(t, kind, process, instance, activity, None, None, "pkg", {}, seq))
        by_raw.raw(t, kind, process, instance, activity)
    assert by_event.counts == by_raw.counts == {"any_done": 3, "alarms": 2, "in_notify": 2}
    assert by_event.values() == by_raw.values()
