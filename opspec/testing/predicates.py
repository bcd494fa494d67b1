"""Trace predicates that read like the spec, for ``assert holds(result, ...)`` and ``check``.

::

    from opspec.testing.predicates import check, count, happens_before, holds, never, within

    assert holds(result, within("sound_alarm", "press_report", 60))
    check(result, happens_before("sound_alarm", "press_report") & never("notify_caregiver"))
    check(result, (count("dispense") == 1).per_instance("notify_workflow"))

A predicate is judged on each trace of what it is given - a
:class:`~opspec.testing.simulation.SimulationResult` (every replication), an engine
:class:`~opspec.engine.simulation.RunResult`, a plain sequence of
:class:`~opspec.engine.trace.TraceEvent`, or the path of a JSON Lines trace written by
``opspec run --trace`` - and holds when it holds on every one.

The predicates are the one Python vocabulary of the property language
(:mod:`opspec.properties.vocabulary`, re-exported here and by :mod:`opspec.testing`):
``within(a, b, 60)`` is ``bounded_response a b 60s``, ``happens_before(a, b)`` is ``a before
b``, ``never(x)`` is ``never x``, ``count(x) <= 4`` is ``count x <= 4``, ``min_gap("x",
hours=4)`` is ``min_gap x 4h``; the same objects are monitors (``simulate(monitors=[...])``).
Each is judged by feeding the trace to the evaluator a monitor runs online, so both give the
same verdict and the same witness on the same run. The text form is a predicate too:
``holds(result, "min_gap dispense 4h")``. This module judges them on results.

Events are named like monitors: a bare name is an activity's completion, a trigger's raise or
a process's start (``activity:``, ``trigger:``, ``process:`` make it explicit; ``a|b`` is
either); :func:`activity_completed`, :func:`event` and any ``Callable[[TraceEvent], bool]``
select events too. Names are checked against the spec (of a
``SimulationResult``, or ``spec=``): one the spec lacks raises
:class:`~opspec.errors.ConfigurationError` listing the names it has.

:func:`check` raises ``AssertionError`` with the claim, why it failed, and the few events
around the violation (marked ``>``), not the whole trace.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties import vocabulary
from opspec.properties.language import trace_end
from opspec.properties.vocabulary import Match, Predicate, as_predicate

#: the judging here; the predicates themselves are the one vocabulary's, handed out here too
__all__ = ["check", "failure_slice", "failures", "holds", "trace_slice",
           *vocabulary.__all__]


def __getattr__(name: str) -> Any:
    if name in vocabulary.__all__:
        return getattr(vocabulary, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: events shown before / after each focus event of a failure, and at most in all
BEFORE, AFTER, MAX_LINES = 4, 2, 14


@dataclass(frozen=True, slots=True)
class _Run:
    label: str                          # "" or " (replication 3)"
    events: Sequence[TraceEvent]
    end: float                          # simulated end of the run (windows after it: unjudged)


# ---------------------------------------------------------------- judging results
def _runs(obj: Any, who: str) -> list[_Run]:
    __tracebackhide__ = True
    from opspec.engine.simulation import RunResult

    if isinstance(obj, RunResult):
        if obj.trace is None:
            raise ConfigurationError("this run kept no trace",
                                     hint="run it with keep_trace=True")
        return [_Run("", obj.trace, float(obj.summary.get("time", _end(obj.trace))))]
    traces = getattr(obj, "traces", None)
    if traces is not None and hasattr(obj, "runs"):      # a SimulationResult
        horizon = getattr(obj, "horizon", None)
        many = len(traces) > 1
        return [_Run(f" (replication {i})" if many else "", t,
                     float(horizon) if horizon is not None else _end(t))
                for i, t in enumerate(traces)]
    if isinstance(obj, (str, os.PathLike)):               # a stored trace (opspec run --trace)
        from opspec.engine.trace_sinks import read_trace

        if not os.path.isfile(obj):     # not a FileNotFoundError through the trace reader
            raise ConfigurationError(
                f"{os.fspath(obj)}: no trace file there (looked at {os.path.abspath(obj)})",
                hint="a relative path is from the folder pytest runs in; write a trace with "
                     "opspec run SPEC --trace FILE, or judge simulate()'s result itself")
        events = list(read_trace(os.fspath(obj)))
        return [_Run("", events, trace_end(events))]
    if isinstance(obj, Sequence) and all(isinstance(e, TraceEvent) for e in obj):
        return [_Run("", obj, trace_end(obj))]
    from opspec.testing.simulation import not_a_result

    raise not_a_result(obj, who, "a SimulationResult, a RunResult, a sequence of TraceEvent or "
                                 "the path of a JSON Lines trace")


def _end(trace: Sequence[TraceEvent]) -> float:
    return trace_end(trace)


def _names(obj: Any, spec: Any) -> Any:
    if spec is None:
        return getattr(obj, "names", None)
    if hasattr(spec, "activities") and hasattr(spec, "triggers"):
        return spec
    from opspec.engine.compiled import CompiledPackage, compile_package
    from opspec.testing.simulation import load_spec_file, spec_names

    if isinstance(spec, (str, os.PathLike)):
        spec = load_spec_file(os.fspath(spec))
    compiled = spec if isinstance(spec, CompiledPackage) else compile_package(spec)
    return spec_names(compiled)


def check_names(predicate: Predicate, names: Any) -> None:
    """:class:`ConfigurationError` when ``predicate`` names something the spec lacks."""
    for subject in predicate.subjects():
        subject.bind(names)
    for process in predicate.processes():
        if process not in names.processes:
            raise ConfigurationError(f"the spec has no process {process!r}",
                                     hint="its processes are: " + ", ".join(names.processes))


def failures(obj: Any, predicate: Predicate | str | Match, *, spec: Any = None,
             first: bool = True, who: str = "failures") -> list[str]:
    """The failure messages of ``predicate`` on each trace of ``obj`` (the first only, by
    default); empty when it holds. ``who`` names the caller in a wrong argument's error."""
    __tracebackhide__ = True
    predicate = as_predicate(predicate)
    names = _names(obj, spec)
    if names is not None:
        check_names(predicate, names)
        predicate = predicate.bind(names)
    out = []
    for run in _runs(obj, who):
        failure = predicate.fail(run.events, run.end)
        if failure is None:
            continue
        lines = [f"expected {predicate.describe()}" + run.label,
                 *(f"  {line}" for line in failure.lines)]
        lines.extend(failure_slice(failure.trace or run.events, failure.focus))
        out.append("\n".join(lines))
        if first:
            break
    return out


def holds(obj: Any, predicate: Predicate | str | Match, *, spec: Any = None) -> bool:
    """Whether ``predicate`` holds on every trace of ``obj``. Names the spec lacks raise
    :class:`ConfigurationError` (they are a mistake in the test, not a failed claim)."""
    __tracebackhide__ = True
    return not failures(obj, predicate, spec=spec, who="holds")


def check(obj: Any, *predicates: Predicate | str | Match, spec: Any = None) -> None:
    """Assert every predicate on ``obj``; ``AssertionError`` with each failure's claim,
    reason and trace slice."""
    __tracebackhide__ = True
    messages = []
    for predicate in predicates:     # a loop, not a comprehension: no frame of ours shown
        messages.extend(failures(obj, predicate, spec=spec, who="check"))
    if messages:
        seed = getattr(obj, "seed", None)
        if seed is not None and hasattr(obj, "replications"):
            messages.append(f"(seed {seed}, {obj.replications} replication(s))")
        raise AssertionError("\n\n".join(messages))


def failure_slice(trace: Sequence[TraceEvent], witness: Sequence[TraceEvent]) -> list[str]:
    """What a failure shows of the trace: the witness events marked in their context, or,
    when nothing happened to show (``eventually``), how the trace ends."""
    from opspec.testing.expectations import format_events

    if witness or not trace:
        return trace_slice(trace, witness)
    return ["  the trace ends with:", *format_events(list(trace[-BEFORE:]))]


def trace_slice(trace: Sequence[TraceEvent], focus: Sequence[TraceEvent]) -> list[str]:
    """A few events around each focus event (marked ``>``), ``...`` between the pieces."""
    from opspec.testing.expectations import format_events

    if not focus or not trace:
        return []
    index = {id(e): i for i, e in enumerate(trace)}
    marked = {index[id(e)] for e in focus if id(e) in index}
    if not marked:
        return ["  trace (relevant events):", *format_events(list(focus)[:MAX_LINES])]
    keep: set[int] = set()
    for i in sorted(marked):
        keep.update(range(max(0, i - BEFORE), min(len(trace), i + AFTER + 1)))
    rows = sorted(keep)
    if len(rows) > MAX_LINES:      # keep the marked rows and their closest neighbours
        rows = sorted(sorted(rows, key=lambda r: min(abs(r - m) for m in marked))[:MAX_LINES])
    lines = [f"  trace around it ({len(marked)} marked event(s) of {len(trace)}):"]
    previous = None
    for r in rows:
        if previous is not None and r != previous + 1:
            lines.append("    ...")
        (text,) = format_events([trace[r]])
        lines.append((">" + text[1:]) if r in marked else text)
        previous = r
    return lines

