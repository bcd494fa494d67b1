"""Build the engine's hot modules as C extensions with mypyc (pyproject.toml holds the rest).

The engine is written in plain, typed Python; mypyc compiles the modules listed in
``opspec/_native.py`` (the interpreter, instances, metrics, the stochastic user's performer…)
so a simulated dose cycle runs about twice as fast — see ``benchmarks/dispenser_day.py``.
Nothing else changes: the same source runs uncompiled when

- ``OPSPEC_PURE_PYTHON=1`` is set while installing (nothing is compiled), or
- there is no C compiler or the compilation fails (a warning says so; the install goes on), or
- a compiled module's source changed after the build (``opspec._native`` notices at import and
  runs all of them from source, so an edit in an editable checkout is never shadowed by a
  stale build; reinstall to compile again).

After compiling, ``opspec/_native_build.json`` records the SHA-256 of each compiled source.
"""

from __future__ import annotations

import json
import os
import runpy
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
NATIVE = runpy.run_path(str(ROOT / "opspec" / "_native.py"))
MODULES: tuple[str, ...] = NATIVE["MODULES"]
STAMP: str = NATIVE["STAMP"]
source_digest = NATIVE["source_digest"]
unlisted_extensions = NATIVE["unlisted_extensions"]


def _wanted() -> bool:
    return os.environ.get("OPSPEC_PURE_PYTHON", "").strip() in ("", "0")


class OptionalNativeBuild(build_ext):
    """build_ext that records what it compiled, and falls back to pure Python on failure."""

    def run(self) -> None:
        if self.inplace:
            _remove_unlisted_extensions()
        try:
            super().run()
        except Exception as error:  # noqa: BLE001 - any compiler failure: install pure Python
            self._pure(f"compiling the engine with mypyc failed ({error})")
            return
        if not self.extensions:
            # Nothing was compiled (pure Python asked for, no mypyc, or mypyc refused the
            # source: said above). A record of this source would vouch for the extensions an
            # earlier in-place build left, and opspec._native would run that older code as
            # this source's compiled build; with no record it runs the source.
            self._unstamp()
            return
        self._stamp()

    def _stamp(self) -> None:
        digests = _READ or _digests()
        text = json.dumps({"compiler": "mypyc", "modules": digests}, indent=1) + "\n"
        targets = [ROOT / "opspec" / STAMP] if self.inplace else []
        targets.append(Path(self.build_lib) / "opspec" / STAMP)
        for target in targets:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text, encoding="utf-8")

    def _pure(self, why: str) -> None:
        print(f"warning: {why}; opspec is installed as pure Python (same results, slower "
              f"engine)", file=sys.stderr)
        self._unstamp()

    def _unstamp(self) -> None:
        stale = ROOT / "opspec" / STAMP
        if self.inplace and stale.exists():
            stale.unlink()


def _remove_unlisted_extensions() -> None:
    """Delete compiled modules an earlier build left in the checkout that are no longer in
    MODULES: Python would import them instead of their source, and opspec._native only guards
    the listed ones."""
    for path in unlisted_extensions(ROOT):
        print(f"removing {path.relative_to(ROOT)} (no longer compiled)", file=sys.stderr)
        path.unlink()


#: setup.py commands that only describe the package: pip runs this file for them before it
#: builds (egg_info for the build requirements, dist_info for the metadata), and mypyc's type
#: check and C generation (about 12 CPU-s) need not run for them.
_METADATA_ONLY = frozenset({"egg_info", "dist_info"})


def _builds() -> bool:
    commands = [argument for argument in sys.argv[1:] if not argument.startswith("-")]
    return not commands or commands[0] not in _METADATA_ONLY


#: The sources' digests when mypyc read them: the record of the build must describe the code
#: compiled, so a source edited while the C compiler runs is found stale by opspec._native
#: (and runs from source) rather than recorded as what was compiled.
_READ: dict[str, str] = {}


def _digests() -> dict[str, str]:
    return {module: source_digest(ROOT / (module.replace(".", "/") + ".py"))
            for module in MODULES}


def _extensions() -> list[object]:
    if not _wanted() or not _builds():
        return []
    try:
        from mypyc.build import mypycify
    except ImportError:
        print("warning: mypyc is not available; opspec is installed as pure Python",
              file=sys.stderr)
        return []
    paths = [module.replace(".", "/") + ".py" for module in MODULES]
    _READ.update(_digests())
    try:
        extensions = list(mypycify(paths, group_name="opspec", opt_level="3", debug_level="0"))
    except (Exception, SystemExit) as error:  # noqa: BLE001 - mypyc refused the source
        _READ.clear()
        print(f"warning: mypyc cannot compile the engine ({error}); opspec is installed as "
              f"pure Python", file=sys.stderr)
        return []
    if sys.platform.startswith("linux"):
        for extension in extensions:
            extension.extra_compile_args = [*extension.extra_compile_args, *_ELF_FLAGS]
    return extensions


#: The compiled engine calls into libpython at almost every step (reference counts aside:
#: dict look-ups, allocation, attribute access). An ELF build calls another shared object's
#: function through a PLT stub, an extra jump each time; ``-fno-plt`` calls it through the
#: GOT directly. The periodic path 2-3 % faster, the dispenser about 2 %
#: (docs/engine-performance.md). The same code and results: only how a call is made.
_ELF_FLAGS = ("-fno-plt",)


setup(ext_modules=_extensions(), cmdclass={"build_ext": OptionalNativeBuild})
