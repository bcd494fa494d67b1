"""Executable specification tests: run specs in pytest and check what they do.

* :mod:`~opspec.testing.plugin` - the pytest plugin (``spec``/``simulate`` fixtures,
  ``--opspec-seed``, ``--device-url``, scenario-file collection), loaded by pytest through the
  ``pytest11`` entry point;
* :mod:`~opspec.testing.simulate` - :func:`simulate` for one or many users, and its result;
* :mod:`~opspec.testing.script` - scripted users as plain data;
* :mod:`~opspec.testing.expectations` - readable ``then`` lines and :func:`expect`;
* :mod:`~opspec.testing.scenario` - ``*.scenario.toml`` files.

Names are loaded lazily so that importing :mod:`opspec.testing` stays light (no pytest, no
numpy until used). The guide is ``docs/spec-testing.md``.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "InstanceRun",
    "Script",
    "ScriptUser",
    "SimulationResult",
    "expect",
    "load_scenarios",
    "load_script",
    "parse_expectation",
    "parse_script",
    "simulate",
    "simulator_for",
]

_WHERE = {
    "InstanceRun": "opspec.testing.simulate",
    "SimulationResult": "opspec.testing.simulate",
    "simulate": "opspec.testing.simulate",
    "Script": "opspec.testing.script",
    "ScriptUser": "opspec.testing.script",
    "load_script": "opspec.testing.script",
    "parse_script": "opspec.testing.script",
    "expect": "opspec.testing.expectations",
    "parse_expectation": "opspec.testing.expectations",
    "load_scenarios": "opspec.testing.scenario",
    "simulator_for": "opspec.testing.plugin",
}


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'opspec.testing' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)
