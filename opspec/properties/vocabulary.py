"""The property language in Python: one set of constructors for every use of a property.

::

    from opspec.testing import check, count, min_gap, never, simulate, within

    result = simulate(spec, users=50, monitors=[min_gap("dispense", hours=4)])   # online
    check(result, within("sound_alarm", "press_report", 60) & never("notify_caregiver"))

Each constructor gives a :class:`Predicate`: a claim about one run's trace, judged by the
evaluator of :mod:`opspec.properties.language` (so it has the same verdict and the same
witness as the property's text form). The same object serves every use:

* as a **monitor**, watched while a run happens (``simulate(monitors=[...])``, the spec's
  ``opspec:Monitor``): :meth:`Predicate.monitor` is its
  :class:`~opspec.properties.language.Property`;
* as a **trace predicate** on stored traces (``holds``, ``check`` in :mod:`opspec.testing`),
  combined with ``&``, ``|``, ``~`` and scoped with :meth:`Predicate.per_instance` (a
  combination is a predicate only: a monitor is one property).

=============================================  =============================================
Python                                         text form
=============================================  =============================================
``never("A")``, ``eventually("A")``            ``never A``, ``eventually A``
``within("A", "B", 900)``                      ``bounded_response A B 15min``
``within("A", "B", math.inf)``                 ``response A B``
``happens_before("A", "B", each=False)``       ``A before B`` (``A before each B``)
``count("A") <= 4``, ``.between(lo, hi)``      ``count A <= 4``, ``count A in [lo, hi]``
``min_gap("A", hours=4)``                      ``min_gap A 4h``
``max_count_per("A", 4, hours=24)``            ``max_count A 4 per 24h``
``never_while("A", after="B", until="C")``     ``never_while A after B until C``
``monitor("...")``                             any text form
=============================================  =============================================

Events are named like monitors: a bare name is an activity's completion, a trigger's raise or
a process's start (``activity:``, ``trigger:``, ``process:`` make it explicit; ``a|b`` is
either); :func:`activity_completed`, :func:`event` and any ``Callable[[TraceEvent], bool]``
select events too (such a predicate is judged on every event, so as a monitor it sees the
whole trace).

Its parts: a predicate and its combinations (:mod:`opspec.properties.predicate`), the simple
predicates - an event that happens, a property that holds, ``never``, ``eventually`` -
(:mod:`opspec.properties.simple_predicates`), events selected by kind and fields
(:mod:`opspec.properties.event_selectors`) and the other properties spelt in Python
(:mod:`opspec.properties.property_terms`); every name is importable from here.

Pure Python (no pytest): usable by any layer above the property language.
"""

from __future__ import annotations

from opspec.properties.event_selectors import (
    activity_completed,
    activity_started,
    event,
    process_started,
    trigger_raised,
)
from opspec.properties.predicate import Failure, Predicate, per_instance
from opspec.properties.property_terms import (
    Count,
    count,
    happens_before,
    max_count_per,
    min_gap,
    monitor,
    never_while,
    within,
)
from opspec.properties.simple_predicates import Match, as_predicate, eventually, never

__all__ = [
    "Count",
    "Failure",
    "Match",
    "Predicate",
    "activity_completed",
    "activity_started",
    "as_predicate",
    "count",
    "event",
    "eventually",
    "happens_before",
    "max_count_per",
    "min_gap",
    "monitor",
    "never",
    "never_while",
    "per_instance",
    "process_started",
    "trigger_raised",
    "within",
]
