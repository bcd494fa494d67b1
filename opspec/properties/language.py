"""One property language for monitors, trace predicates and scenario ``then`` lines.

A :class:`Property` is a claim about one run's trace ("no two dispenses closer than 4 h",
"every alarm is answered within 15 min"). The same property is

* watched **online** while a simulation runs: :meth:`Property.start` gives a
  :class:`MonitorRun`, a trace listener with a ``selects`` set (the engine builds only the
  events it needs) - what ``opspec:Monitor``, ``opspec run``, ``opspec evaluate`` and
  ``simulate(monitors=...)`` use;
* judged **offline** over a stored trace: :meth:`Property.judge` feeds the same
  :class:`MonitorRun` the trace's events one by one - what the trace predicates
  (:mod:`opspec.testing.predicates`) and the ``then`` lines of scenario files use.

One evaluator, fed the same events, so a monitor and a predicate with the same text give the
same verdict and the same witness (the events that show a violation) on the same run.

The text form (``min_gap dispense 4h``, ``bounded_response sound_alarm dispense 15 min``)
is read by :mod:`opspec.properties.text_form`; what a property counts (a *subject*: an
activity, a trigger or a process) is :mod:`opspec.properties.subjects`.

The verdicts follow the specification patterns of Dwyer, Avrunin and Corbett (ICSE 1999) read
over the finite trace, in its order (``seq``: events at the same instant count in the order
the engine emitted them), and docs/spec-testing.md ("What a property means") states the
boundary cases: an event exactly at a bound is in time, an event that is both ``A`` and ``B``
answers (or precedes) itself, and a time window the end of the run cuts off is *open* - not
judged - while an untimed obligation (``eventually``, ``response``, ``count ... >=``) still
open at the end is a violation, because the run is the whole time it talks about.

Its parts: the evaluator and the base class (:mod:`opspec.properties.evaluator`), the
properties about how often one subject happens (:mod:`opspec.properties.occurrence`) and
about what comes before or after what (:mod:`opspec.properties.order`); every name is
importable from here.

Pure Python, no wall clock: importable by any layer above the engine.
"""

from __future__ import annotations

from opspec.properties.evaluator import (
    KEEP,
    MonitorResult,
    MonitorRun,
    Property,
    Violation,
    clock,
    trace_end,
)
from opspec.properties.occurrence import (
    COMPARISONS,
    CountBound,
    Eventually,
    MaxCount,
    MinGap,
    Never,
)
from opspec.properties.order import BoundedResponse, NeverWhile, Precedence
from opspec.properties.subjects import (
    Names,
    Selector,
    Subject,
    parse_subject,
)

__all__ = [
    "COMPARISONS",
    "KEEP",
    "BoundedResponse",
    "CountBound",
    "Eventually",
    "MaxCount",
    "MinGap",
    "MonitorResult",
    "MonitorRun",
    "Names",
    "Never",
    "NeverWhile",
    "Precedence",
    "Property",
    "Selector",
    "Subject",
    "Violation",
    "clock",
    "parse_subject",
    "trace_end",
]
