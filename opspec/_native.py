"""Which engine modules run compiled (mypyc) and which run from their Python source.

``setup.py`` compiles :data:`MODULES` with mypyc when opspec is installed and records each
source's SHA-256 in ``opspec/_native_build.json``. At ``import opspec`` :func:`install` checks
that record: when ``OPSPEC_PURE_PYTHON=1`` is set, or when any compiled module's source changed
since the build (an edit in an editable checkout, a branch switch), *all* of them are imported
from source instead — a stale build must never shadow the code being edited, and compiled and
source versions of these modules do not mix (``Simulation`` subclasses ``Interpreter``).
Either way the results are the same; only the speed differs. ``opspec --version`` says which.

This module imports nothing from opspec: ``setup.py`` runs it before opspec is installed.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import json
import os
import sys
from pathlib import Path
from typing import Any

#: The modules compiled by mypyc: the interpreter's hot path, per dose cycle. Left out: clock
#: (its Clock subclasses simpy.Environment, and a native class cannot inherit a Python one);
#: measured and left out: condition_values (slower compiled), the distributions (slotted frozen dataclasses that
#: mypyc cannot subclass), processors (a mypyc internal error), monitors (mypyc rejects an
#: overridden attribute type), the user model's data classes (errors, model, routine: ~5 % faster
#: compiled, but mypyc enforces their annotations at construction, so ``Window("out", "14:00",
#: ...)`` and ``Omission("x")`` raised a bare TypeError instead of accepting the time of day or
#: naming the bad parameter).
MODULES: tuple[str, ...] = (
    "opspec.engine.activities",
    "opspec.engine.compiled",
    "opspec.engine.compiling.constructs",
    "opspec.engine.compiling.context",
    "opspec.engine.compiling.graphs",
    "opspec.engine.conditions",
    "opspec.engine.coordinating",
    "opspec.engine.dedicated",
    "opspec.engine.escalations",
    "opspec.engine.flow",
    "opspec.engine.instances",
    "opspec.engine.interpreter",
    "opspec.engine.joins",
    "opspec.engine.lanes",
    "opspec.engine.lifecycle",
    "opspec.engine.lone",
    "opspec.engine.metrics",
    "opspec.engine.multi_instance",
    "opspec.engine.offers",
    "opspec.engine.process_deadlines",
    "opspec.engine.part",
    "opspec.engine.random",
    "opspec.engine.runstate",
    "opspec.engine.sampling",
    "opspec.engine.scope",
    "opspec.engine.simulation",
    "opspec.engine.timed_calls",
    "opspec.engine.timers",
    "opspec.engine.timing",
    "opspec.engine.tools",
    "opspec.engine.triggers",
    "opspec.engine.workitem",
    "opspec.usermodels.performer",
    "opspec.worlds.room_devices",
    "opspec.worlds.stepping",
)
STAMP = "_native_build.json"
ENV = "OPSPEC_PURE_PYTHON"

_PACKAGE_ROOT = Path(__file__).resolve().parent.parent


def source_digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _source(module: str) -> Path:
    return _PACKAGE_ROOT / (module.replace(".", "/") + ".py")


def _has_extension(module: str) -> bool:
    base = _source(module).with_suffix("")
    return any(Path(f"{base}{suffix}").exists()
               for suffix in importlib.machinery.EXTENSION_SUFFIXES)


def _decide() -> tuple[bool, str]:
    """(compiled?, why) for this installation."""
    if os.environ.get(ENV, "").strip() not in ("", "0"):
        return False, f"pure Python ({ENV} is set)"
    if not any(_has_extension(module) for module in MODULES):
        return False, "pure Python (installed without compiling; see setup.py)"
    try:
        recorded: dict[str, Any] = json.loads(
            (_PACKAGE_ROOT / "opspec" / STAMP).read_text(encoding="utf-8"))["modules"]
    except (OSError, ValueError, KeyError, TypeError):
        return False, f"pure Python (no valid opspec/{STAMP}: reinstall to compile)"
    for module in MODULES:
        try:
            changed = recorded.get(module) != source_digest(_source(module))
        except OSError:
            changed = True
        if changed:
            return False, (f"pure Python ({module} changed since it was compiled: reinstall, "
                           f"e.g. pip install -e ., to compile it again)")
    return True, f"compiled with mypyc ({len(MODULES)} modules)"


def _left_compiled() -> frozenset[str]:
    """Modules an earlier build compiled that are no longer in :data:`MODULES` (a module
    taken out of the list, then a branch switch or a pull in an editable checkout): their
    stale extension would shadow the source, since Python prefers an extension module."""
    try:
        recorded = json.loads((_PACKAGE_ROOT / "opspec" / STAMP).read_text(encoding="utf-8"))
        built = set(recorded["modules"])
    except (OSError, ValueError, KeyError, TypeError):
        return frozenset()
    return frozenset(m for m in built - set(MODULES) if _has_extension(m))


def unlisted_extensions(root: Path) -> list[Path]:
    """Compiled modules under ``root``/opspec that are not in :data:`MODULES` (an earlier
    build's, left in a checkout): setup.py deletes them before an in-place build, since
    Python would import them instead of their source."""
    listed = {root / module.replace(".", "/") for module in MODULES}
    # longest first: 'flow.cpython-311-x86_64-linux-gnu.so' also ends in the bare '.so', and
    # read with that suffix it would name a module 'flow.cpython-311-x86_64-linux-gnu'
    suffixes = sorted(importlib.machinery.EXTENSION_SUFFIXES, key=len, reverse=True)
    found = []
    for path in sorted((root / "opspec").rglob("*")):
        suffix = next((s for s in suffixes if path.name.endswith(s)), None)
        if suffix is not None and path.with_name(path.name[: -len(suffix)]) not in listed:
            found.append(path)
    return found


class _FromSource:
    """Meta-path finder importing modules from their .py files, not the extensions: the
    :data:`MODULES` when they must not run compiled, and always those no longer in it."""

    def __init__(self, modules: frozenset[str]) -> None:
        self.modules = modules

    def find_spec(self, name: str, path: object = None, target: object = None
                  ) -> importlib.machinery.ModuleSpec | None:
        if name not in self.modules:
            return None
        return importlib.util.spec_from_file_location(name, _source(name))


COMPILED = False
STATUS = "pure Python"


def install() -> None:
    """Decide once per process; route the modules to their source when they must not run
    compiled (idempotent)."""
    global COMPILED, STATUS
    COMPILED, STATUS = _decide()
    if any(isinstance(f, _FromSource) for f in sys.meta_path):
        return
    routed = set(_left_compiled())
    if not COMPILED and any(_has_extension(module) for module in MODULES):
        routed.update(MODULES)
    if routed:
        sys.meta_path.insert(0, _FromSource(frozenset(routed)))
