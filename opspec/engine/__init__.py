"""The engine: compiled packages executed on a SimPy clock (``clock``) (see ``simulation``).

Import what you need from the submodules; the names below are loaded lazily so that
``import opspec.engine`` stays light.
"""

from __future__ import annotations

from opspec.lazy_names import lazy_names

__all__ = [
    "CallablePerformer",
    "CompiledPackage",
    "EngineConfig",
    "JsonlSink",
    "MemorySink",
    "MetricsListener",
    "PerformerRegistry",
    "RunResult",
    "ScriptedUser",
    "SimulatedDevice",
    "Simulation",
    "compile_package",
    "read_trace",
]

_WHERE = {
    "CallablePerformer": "opspec.engine.builtin_performers",
    "ScriptedUser": "opspec.engine.builtin_performers",
    "SimulatedDevice": "opspec.engine.builtin_performers",
    "CompiledPackage": "opspec.engine.compiled",
    "compile_package": "opspec.engine.compiled",
    "EngineConfig": "opspec.engine.config",
    "JsonlSink": "opspec.engine.trace_sinks",
    "MemorySink": "opspec.engine.trace_sinks",
    "read_trace": "opspec.engine.trace_sinks",
    "MetricsListener": "opspec.engine.metrics",
    "PerformerRegistry": "opspec.engine.registry",
    "RunResult": "opspec.engine.simulation",
    "Simulation": "opspec.engine.simulation",
}


__getattr__ = lazy_names(__name__, _WHERE)
