"""The public Python API is what the docs say: every name in every ``__all__`` imports, and is
the kind of thing its name says (no submodule shadowing a function of the same name)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import subprocess
import sys
import types
import typing
from collections.abc import Iterator

import pytest

import opspec


def _modules() -> Iterator[str]:
    yield "opspec"
    for info in pkgutil.walk_packages(opspec.__path__, "opspec."):
        if info.name != "opspec.__main__":
            yield info.name


MODULES = sorted(_modules())


def _alias(obj: object) -> bool:
    """A type alias (``Evaluator = Callable[...]``, ``Marking = tuple[int, ...]``)."""
    return isinstance(obj, types.GenericAlias) or typing.get_origin(obj) is not None


def _kind_problem(name: str, obj: object) -> str | None:
    if isinstance(obj, types.ModuleType):
        return f"{name} is a module ({obj.__name__}), not what __all__ promises"
    if name.startswith("__"):                            # __version__
        return None if isinstance(obj, str) else f"{name} is a {type(obj).__name__}"
    if name.isupper():                                   # a constant
        if inspect.isclass(obj) or inspect.isfunction(obj):
            return f"constant {name} is a {type(obj).__name__}"
        return None
    if name[0].isupper():                                # a class, or a type alias
        if inspect.isclass(obj) or _alias(obj):
            return None
        return f"{name} is a {type(obj).__name__}, not a class"
    if callable(obj) and not inspect.isclass(obj):       # a function
        return None
    return f"{name} is a {type(obj).__name__}, not a function"


@pytest.mark.parametrize("module", MODULES)
def test_every_name_in_all_imports_and_is_of_its_kind(module: str) -> None:
    mod = importlib.import_module(module)
    problems = []
    for name in getattr(mod, "__all__", ()):
        try:
            obj = getattr(mod, name)
        except AttributeError:
            problems.append(f"{name} is in __all__ but does not import")
            continue
        problem = _kind_problem(name, obj)
        if problem is not None:
            problems.append(problem)
    assert problems == [], f"{module}: " + "; ".join(problems)


def test_the_documented_import_paths() -> None:
    from opspec import RunOutcome, User, run
    from opspec.request import run as run_spec
    from opspec.runs import RunOutcome as Outcome

    # opspec.run is opspec.request.run: it fills the one request every door fills
    assert inspect.isfunction(run) and inspect.isfunction(run_spec)
    assert RunOutcome is Outcome and inspect.isclass(User)
    assert inspect.signature(run_spec).return_annotation in ("RunOutcome", RunOutcome)
    assert "RunOutcome" in (run.__doc__ or "")
    assert "run" in opspec.__all__ and "RunOutcome" in opspec.__all__


def test_opspec_testing_simulate_is_the_function_even_after_its_module_is_imported() -> None:
    # the regression: a submodule named ``simulate`` shadowed the function once imported
    code = ("import opspec.testing.simulation, opspec.testing.plugin;"
            "from opspec.testing import simulate, SimulationResult;"
            "import inspect;"
            "print(inspect.isfunction(simulate), simulate.__module__,"
            " inspect.isclass(SimulationResult))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["True", "opspec.testing.simulation", "True"]
