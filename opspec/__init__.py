"""opspec: execute operational specifications (XPDL / SISARL-XPDL) of assistive devices and
their users, for usability evaluation, walkthroughs, specification tests and hardware in the loop.

Run a spec from Python with :func:`opspec.run` (:mod:`opspec.runs`, which builds every run)::

    import opspec

    outcome = opspec.run("specs/medication_dispenser.xpdl", seed=1, days=7)
    outcome.metrics["doses_taken"]

Importing ``opspec`` stays light: no lxml, Textual or pyserial is imported here.
"""

from opspec import _native

_native.install()      # the engine compiled with mypyc, or from source if that build is stale

from typing import Any

__version__ = "0.1.0"
__all__ = ["RunOutcome", "User", "__version__", "run"]

#: The public way to run a spec from Python (docs/architecture.md): ``opspec.run(spec, ...)``
#: returns a ``RunOutcome``; both live in :mod:`opspec.runs`, loaded on first use.
_RUNS = frozenset({"RunOutcome", "User", "run"})


def __getattr__(name: str) -> Any:
    if name in _RUNS:
        import importlib

        return getattr(importlib.import_module("opspec.runs"), name)
    raise AttributeError(f"module 'opspec' has no attribute {name!r}")
