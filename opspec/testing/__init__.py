"""Executable specification tests: run specs in pytest and check what they do.

* :mod:`~opspec.testing.plugin` - the pytest plugin (``spec``/``simulate`` fixtures,
  ``--opspec-seed``, ``--device-url``, scenario-file collection), loaded by pytest through the
  ``pytest11`` entry point;
* :mod:`~opspec.testing.simulation` - :func:`simulate` for one or many users, and its result;
* :mod:`~opspec.usermodels.scripts` (also as ``opspec.testing.script``) - scripted users as
  plain data;
* :mod:`~opspec.testing.expectations` - readable ``then`` lines and :func:`expect`;
* :mod:`~opspec.testing.scenario` - ``*.scenario.toml`` files;
* :mod:`~opspec.properties.vocabulary` - the property language in Python, one set of
  constructors for monitors and trace predicates (``within``, ``never``, ``min_gap``, ...);
* :mod:`~opspec.testing.predicates` - judging them on results (``holds``, ``check``);
* :mod:`~opspec.testing.golden` - golden traces with readable diffs;
* :mod:`~opspec.testing.assertions` - statistical assertions and their numeric core;
* :mod:`~opspec.testing.monitors` - the report of the monitors watched in every simulated run
  (``never_happens`` and ``bounded_response`` are deprecated spellings of ``never`` and
  ``within``).

Names are loaded lazily so that importing :mod:`opspec.testing` stays light (no pytest, no
numpy until used). The guide is ``docs/spec-testing.md``.
"""

from __future__ import annotations

from opspec.lazy_names import lazy_names

__all__ = [
    "InstanceRun",
    "Script",
    "ScriptUser",
    "SimulationResult",
    "activity_completed",
    "activity_started",
    "assert_mean",
    "assert_no_violations",
    "assert_quantile",
    "assert_rate",
    "assert_rate_sequential",
    "bounded_response",
    "check",
    "count",
    "event",
    "eventually",
    "expect",
    "happens_before",
    "holds",
    "load_scenarios",
    "load_script",
    "max_count_per",
    "min_gap",
    "monitor",
    "never",
    "never_happens",
    "never_while",
    "parse_expectation",
    "parse_script",
    "per_instance",
    "process_started",
    "simulate",
    "simulator_for",
    "trigger_raised",
    "within",
]

_WHERE = {
    "InstanceRun": "opspec.testing.simulation",
    "SimulationResult": "opspec.testing.simulation",
    "simulate": "opspec.testing.simulation",
    "Script": "opspec.usermodels.scripts",
    "ScriptUser": "opspec.usermodels.scripts",
    "load_script": "opspec.usermodels.scripts",
    "parse_script": "opspec.usermodels.scripts",
    "expect": "opspec.testing.expectations",
    "parse_expectation": "opspec.testing.expectations",
    "load_scenarios": "opspec.testing.scenario",
    "simulator_for": "opspec.testing.plugin",
    "activity_completed": "opspec.properties.vocabulary",
    "check": "opspec.testing.predicates",
    "count": "opspec.properties.vocabulary",
    "event": "opspec.properties.vocabulary",
    "eventually": "opspec.properties.vocabulary",
    "happens_before": "opspec.properties.vocabulary",
    "holds": "opspec.testing.predicates",
    "never": "opspec.properties.vocabulary",
    "per_instance": "opspec.properties.vocabulary",
    "process_started": "opspec.properties.vocabulary",
    "trigger_raised": "opspec.properties.vocabulary",
    "within": "opspec.properties.vocabulary",
    "assert_mean": "opspec.testing.assertions",
    "assert_quantile": "opspec.testing.assertions",
    "assert_rate": "opspec.testing.assertions",
    "assert_rate_sequential": "opspec.testing.assertions",
    "activity_started": "opspec.properties.vocabulary",
    "assert_no_violations": "opspec.testing.monitors",
    "bounded_response": "opspec.testing.monitors",
    "max_count_per": "opspec.properties.vocabulary",
    "min_gap": "opspec.properties.vocabulary",
    "monitor": "opspec.properties.vocabulary",
    "never_happens": "opspec.testing.monitors",
    "never_while": "opspec.properties.vocabulary",
}


__getattr__ = lazy_names(__name__, _WHERE)
