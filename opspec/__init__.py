"""opspec: execute operational specifications (XPDL / SISARL-XPDL) of assistive devices and
their users, for usability evaluation, walkthroughs, specification tests and hardware in the loop.

Run a spec from Python with :func:`opspec.run` (:mod:`opspec.runs`, which builds every run)::

    import opspec

    outcome = opspec.run("specs/medication_dispenser.xpdl", seed=1, days=7)
    outcome.metrics["doses_taken"]

Importing ``opspec`` stays light: no lxml, Textual or pyserial is imported here.
"""

import os

# numpy's OpenBLAS starts a server thread per core when numpy is first imported, and each
# spins for about 0.1 CPU-s before it sleeps, whether or not a BLAS routine is ever called.
# opspec's numpy work (random streams, small statistics) gains nothing from those threads, and
# it runs replications in processes of their own: the spinning only took CPU from the run
# beside it (25 % of an hour of the vacuum cleaner, docs/engine-performance.md). A value the
# user set is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from opspec import _native

_native.install()      # the engine compiled with mypyc, or from source if that build is stale

from typing import Any

__version__ = "0.1.0"
__all__ = ["RunOutcome", "User", "__version__", "run"]

#: ``RunOutcome`` and ``User`` live in :mod:`opspec.runs`, loaded on first use.
_RUNS = frozenset({"RunOutcome", "User"})


def run(spec: Any, **options: Any) -> Any:
    """Run ``spec`` once, as ``opspec run`` does, and return its ``opspec.RunOutcome`` (typed
    ``Any`` here so that ``import opspec`` imports nothing of the layers below): the public
    way to run a spec from Python (docs/architecture.md).

    The options are those of :func:`opspec.request.run` (``seed``, ``days``, ``until``,
    ``user_model``, ``script``, ``user``, ``no_user``, ``user_index``, ``config``,
    ``performers``, ``listeners``, ``params``, ``keep_trace``): the request every front door
    fills, decided by the same rules (the spec gate of ``opspec validate``, the companion
    user model, scripts checked against the spec). ``script`` is, as with ``opspec run
    --script``, the path of a script file (TOML or JSON), a loaded
    :class:`~opspec.usermodels.scripts.Script` or its steps.
    """
    import importlib

    # imported by name, as the lazy names below: this package's root sits above every layer
    # (it is the public door), while opspec.model.codec imports the root for __version__
    return importlib.import_module("opspec.request").run(spec, **options)


def __getattr__(name: str) -> Any:
    if name in _RUNS:
        import importlib

        return getattr(importlib.import_module("opspec.runs"), name)
    raise AttributeError(f"module 'opspec' has no attribute {name!r}")
