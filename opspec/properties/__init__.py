"""The property language: claims about one run's trace, with their text, meaning and evaluation.

* :mod:`~opspec.properties.language` - the property classes and the one evaluator, fed
  events online (while a run happens) or offline (over a stored trace): the evaluator in
  :mod:`~opspec.properties.evaluator`, how often one subject happens in
  :mod:`~opspec.properties.occurrence`, what comes before or after what in
  :mod:`~opspec.properties.order`;
* :mod:`~opspec.properties.text_form` - the text form (``min_gap dispense 4h``,
  ``bounded_response sound_alarm dispense 15 min``), read into those classes;
* :mod:`~opspec.properties.subjects` - what a property counts: an activity, a trigger or a
  process (``activity:dispense``, ``a|b``);
* :mod:`~opspec.properties.vocabulary` - the language in Python: one set of constructors
  (``never``, ``within``, ``min_gap``, ``count(...) <= n``...) whose objects are monitors and
  trace predicates alike: the predicate and its combinations in
  :mod:`~opspec.properties.predicate`, events and properties as predicates in
  :mod:`~opspec.properties.simple_predicates`, the event selectors in
  :mod:`~opspec.properties.event_selectors`, the terms in
  :mod:`~opspec.properties.property_terms`;
* :mod:`~opspec.properties.monitors` - the monitors a spec declares (``opspec:Monitor``),
  watched in every run (:func:`opspec.runs.build`).

The trace predicates of spec tests (judged by :mod:`opspec.testing.predicates`) and the
``then`` lines of scenario files are this language too (docs/spec-testing.md, "One property
language"). It
sits above the engine (it reads the engine's trace events and a compiled spec's names) and
below the run builder.
"""

from opspec.properties.language import (
    BoundedResponse,
    CountBound,
    Eventually,
    MaxCount,
    MinGap,
    MonitorResult,
    MonitorRun,
    Never,
    NeverWhile,
    Precedence,
    Property,
    Subject,
    Violation,
)
from opspec.properties.monitors import Monitor, declared_monitors, parse_monitor
from opspec.properties.subjects import parse_subject
from opspec.properties.text_form import parse_property

__all__ = [
    "BoundedResponse",
    "CountBound",
    "Eventually",
    "MaxCount",
    "MinGap",
    "Monitor",
    "MonitorResult",
    "MonitorRun",
    "Never",
    "NeverWhile",
    "Precedence",
    "Property",
    "Subject",
    "Violation",
    "declared_monitors",
    "parse_monitor",
    "parse_property",
    "parse_subject",
]
