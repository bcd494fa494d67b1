"""What several commands share: loading a spec (XPDL or ``.wfs``) and choosing the user lane's
performer (a script, a user model, or the spec's companion ``SPEC.users.toml``)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.errors import ConfigurationError

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledPackage
    from opspec.engine.performers import Performer
    from opspec.errors import Diagnostic
    from opspec.model import Package
    from opspec.runs import User

__all__ = ["bind_user", "choose_user", "companion_user_model", "engine_diagnostics",
           "load_any_spec"]


def load_any_spec(path: str | Path, *, command: str | None = None,
                  warnings: list[str] | None = None) -> Package:
    """The package in ``path`` (XPDL or ``.wfs``), refused with every error ``opspec validate``
    reports (a :class:`~opspec.errors.SpecError` listing them with ``path:line``): the run,
    evaluate and walkthrough commands never execute a spec that validation rejects.
    ``.wfs`` scripts (compiled from specs that passed) and paths that are not files open as
    :func:`opspec.xpdl.open_spec.open_spec` does; a file that cannot be read at all (not a
    regular file, no permission) is a ConfigurationError (exit status 2). What
    :func:`engine_diagnostics` adds
    for validate (monitors, the world) is raised as a located ConfigurationError (exit 2)
    when the run builds them, as before.

    With ``command`` (``"run"``, ``"evaluate"``), the warnings ``opspec validate`` prints for
    a spec that loads are printed to stderr as ``opspec COMMAND: path:line: warning: ...``:
    a misspelt directive changes what runs, and must not pass unseen. ``warnings``, when
    given, receives each warning's text (the walkthrough shows them on its screen)."""
    from opspec.xpdl.open_spec import open_spec, refuse_unreadable
    from opspec.xpdl.reader import not_a_file

    target = Path(path)
    if target.suffix == ".wfs" or not_a_file(target) is not None:
        return open_spec(path)
    from opspec.errors import Severity, SpecError
    from opspec.xpdl.validate import validate_spec

    package, report = validate_spec(target)     # monitors and the world: checked as built
    refuse_unreadable(report.diagnostics)       # an unreadable file: exit status 2, not 1
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    if errors or package is None:
        raise SpecError.from_diagnostics(errors or report.diagnostics)
    for warning in report.diagnostics:
        if warning.severity is Severity.WARNING:
            if command is not None:
                print(f"opspec {command}: {warning}", file=sys.stderr)
            if warnings is not None:
                warnings.append(str(warning))
    return package


# The code of what the engine's compilation refuses (compile_package's SpecError).
NOT_RUNNABLE = "not-runnable"


def engine_diagnostics(package: Package, *, world: bool = False) -> list[Diagnostic]:
    """What only the engine and the bindings can judge, as diagnostics: whether the engine
    compiles the package at all (``not-runnable``: what ``run`` would refuse, at its line),
    the monitors the spec declares (``bad-monitor``) and, with ``world``, whether its world
    can be built (``bad-world``: an unknown world, a missing opspec:WorldFile, an unknown parameter, a
    value of the wrong type, a start inside an obstacle)."""
    from opspec.engine.compiled import compile_package
    from opspec.engine.monitors import declared_monitors
    from opspec.errors import Diagnostic, OpspecError, Severity, SourceLocation

    spec_file = SourceLocation(str(getattr(package, "source", None) or "<spec>"))
    try:
        compiled = compile_package(package)
    except OpspecError as error:
        # what the engine refuses, validate refuses: at its line, as the run would say it
        return [Diagnostic(error.location or spec_file, Severity.ERROR, NOT_RUNNABLE,
                           error.message, error.hint or "")]
    out: list[Diagnostic] = []
    try:
        declared_monitors(compiled)
    except ConfigurationError as error:
        out.append(Diagnostic(error.location or spec_file, Severity.ERROR, "bad-monitor",
                              error.message, error.hint or ""))
    if world:
        from opspec.worlds import world_performers

        try:
            world_performers(compiled, seed=0, user=0)
        except ConfigurationError as error:
            out.append(Diagnostic(error.location or spec_file, Severity.ERROR, "bad-world",
                                  error.message, error.hint or ""))
    return out


def companion_user_model(spec_path: str | Path) -> Path | None:
    """``SPEC.users.toml`` next to the spec, if there is one (:mod:`opspec.runs`' rule)."""
    from opspec.runs import companion_user_model as companion

    return companion(spec_path)


def choose_user(compiled: CompiledPackage, spec_path: str | Path, *, script: str | None,
                user_model: str | None, companion: bool = True) -> User:
    """The user-lane performer the options ask for, checked against the spec before any run.

    ``script`` wins over ``user_model``; with neither, the spec's companion user model is used
    when ``companion`` is true and one exists; otherwise nobody performs the user lane.
    """
    from opspec.engine.lanes import user_lane
    from opspec.runs import User

    lane = user_lane(compiled)
    if script is not None and user_model is not None:
        raise ConfigurationError("give --script or --user-model, not both",
                                 hint="a script plays exact actions; a model draws them")
    if script is not None:
        from opspec.engine.names import spec_names
        from opspec.testing.script import load_script

        plan = load_script(script)
        names = spec_names(compiled)         # the same names simulate(script=...) checks
        plan.check_names(names.activities, names.triggers)
        return User.script(plan, f"the script {script}")
    ref: str | Path | None = user_model
    if ref is None and companion:
        ref = companion_user_model(spec_path)
    if ref is None:
        return User.nobody("nobody (no --script or --user-model, and no companion .users.toml): "
                           "user-lane activities wait" if not lane.empty
                           else "nobody (no user lane)")
    user = User.model(ref, f"the user model {ref}")
    if not lane.empty:
        for warning in user.source.validate_against(lane.manual, choices=lane.choices):
            print(f"opspec: {warning}", file=sys.stderr)
    return user


def bind_user(compiled: CompiledPackage, performer: Performer | None) -> dict[str, Any]:
    """Performer bindings giving ``performer`` the whole user lane (empty for nobody)."""
    if performer is None:
        return {}
    from opspec.engine.lanes import user_lane

    return {name: performer for name in user_lane(compiled).bind_names}
