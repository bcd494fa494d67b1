"""Compiling a model package into the engine's runtime tables (:mod:`opspec.engine.compiled`).

- :mod:`~opspec.engine.compiling.context` — the package's tables and how expressions,
  triggers, timers, parameters and data fields compile;
- :mod:`~opspec.engine.compiling.constructs` — the construct table: one small compiler per
  kind of activity body and per aspect of an activity (performer, join, split, loop, …);
- :mod:`~opspec.engine.compiling.graphs` — graphs (transitions, boundary events, starts, OR
  join reach, deferred choices) and processes (start triggers, data).

:func:`opspec.engine.compiled.compile_package` is the entry point.
"""
