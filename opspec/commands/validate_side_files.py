"""The files ``opspec run SPEC`` reads besides the spec, checked by ``opspec validate SPEC``.

A run picks up files beside the spec by their name (:func:`opspec.request.side_files`: the
companion user model ``SPEC.users.toml``) and reads the world file the spec names
(``opspec:WorldFile``). ``validate`` promises that what it accepts runs, so it checks each
side file with the loader the run uses (:func:`opspec.usermodels.load_user_model`, then
:func:`opspec.request.user_model_warnings` against the spec's user lane), reporting what the
run would refuse as an error at the file, line and key the loader gives
(:mod:`opspec.toml_lines`: ``--json`` carries the line as a spec's diagnostic does), the run's
warnings as warnings. The world file is checked
already, with the spec (``bad-world``, :func:`opspec.commands.validate.engine_checks`); here it
is only named in the summary. A side file that is absent is no problem.

When the spec has errors, the user model is still read (what can be checked without the spec)
and a note (``info``) says it was not checked against the spec's user lane, and why.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opspec.errors import Diagnostic, OpspecError, Severity, SourceLocation

__all__ = ["BAD_USER_MODEL", "NOT_CHECKED", "SideFile", "check_side_files"]

#: the code of a companion user model a run would refuse
BAD_USER_MODEL = "bad-user-model"
#: the code of the note saying a side file was not (fully) checked, and why
NOT_CHECKED = "side-file-not-checked"

# Errors that are found only once the engine compiled the spec: the user lane is known then.
_AFTER_COMPILING = frozenset({"bad-world", "bad-monitor"})



@dataclass(frozen=True, slots=True)
class SideFile:
    """A file a run of the spec reads besides it: ``what`` it is (``"user model"``,
    ``"world file"``), whether it was checked as the run checks it and, if not, why."""

    path: Path
    what: str
    checked: bool = True
    why_not: str = ""
    #: given on the command line (``--user-model``), not picked up beside the spec
    given: bool = False

    def to_json(self) -> dict[str, Any]:
        return {"path": str(self.path), "what": self.what, "checked": self.checked,
                "why_not": self.why_not or None, "given": self.given}


def check_side_files(spec_path: Path, package: Any, diagnostics: tuple[Diagnostic, ...],
                     user_model: str | None = None) -> tuple[list[Diagnostic], list[SideFile]]:
    """The problems of the side files of the spec at ``spec_path`` and the files themselves.
    ``package`` is what validate read from the spec (None: nothing could be read) and
    ``diagnostics`` what it found in it, before ``--strict``. ``user_model`` (``--user-model``:
    a file or preset, as ``opspec run``/``evaluate`` take it) is checked instead of the
    companion, as a run given it reads it instead."""
    from opspec.request import side_files

    why = _why_not(package, diagnostics)
    compiled = None
    if why is None:
        compiled, why = _compiled(package)
    found: list[Diagnostic] = []
    files: list[SideFile] = []
    given = user_model is not None
    beside = {"user model": Path(user_model)} if user_model is not None else side_files(
        spec_path)
    for what, path in beside.items():
        problems, checked = _check_user_model(path, compiled)     # the one kind there is
        found.extend(problems)
        if checked or not why:
            files.append(SideFile(path, what, given=given))
            continue
        files.append(SideFile(path, what, checked=False, why_not=why, given=given))
        if not problems:
            found.append(Diagnostic(
                SourceLocation(str(path)), Severity.INFO, NOT_CHECKED,
                f"the {what} {'given' if given else 'beside the spec'} was read but not "
                f"checked against the spec's user lane: {why}",
                "fix the spec, then validate again"))
    files.extend(_world_file(spec_path, package, why))
    return found, files


def _why_not(package: Any, diagnostics: tuple[Diagnostic, ...]) -> str | None:
    """Why the spec's user lane is not known (None: it is)."""
    if package is None:
        return "the spec could not be read"
    if any(d.severity is Severity.ERROR and d.code not in _AFTER_COMPILING
           for d in diagnostics):
        return "the spec has errors"
    return None


def _compiled(package: Any) -> tuple[Any, str | None]:
    from opspec.engine.compiled import compile_package

    try:
        return compile_package(package), None
    except OpspecError:         # reported as not-runnable already
        return None, "the engine does not compile the spec"


def _check_user_model(path: Path, compiled: Any) -> tuple[list[Diagnostic], bool]:
    """What a run would say of the user model at ``path``: read by the run's loader and
    checked against the user lane of ``compiled``, or only read when the spec is not known
    (the bool: checked against it)."""
    from opspec.request import user_model_warnings
    from opspec.usermodels import load_user_model

    try:
        model = load_user_model(path)
        if compiled is None:
            return [], False
        warnings = user_model_warnings(model, compiled)
    except OpspecError as error:
        return [_as_diagnostic(error, path)], compiled is not None
    return list(warnings), True


def _as_diagnostic(error: OpspecError, path: Path) -> Diagnostic:
    """The run's refusal, as validate's error: the same message and hint, at the file, line
    and key the loader gives (a syntax error's line is tomllib's; placed here too for an
    error that arrives without it)."""
    from opspec.toml_lines import syntax_line

    location = error.location or SourceLocation(str(path))
    line = syntax_line(error.message)
    if line is not None and location.line is None and location.key is None:
        location = SourceLocation(location.path, line)
    return Diagnostic(location, Severity.ERROR, BAD_USER_MODEL, error.message, error.hint)


def _world_file(spec_path: Path, package: Any, why: str | None) -> list[SideFile]:
    """The world file the spec names (``opspec:WorldFile``) when the spec declares a world and
    the file is there: checked with the spec (``bad-world``) when the engine compiled it."""
    if package is None or not any(a.name == "opspec:World"
                                  for a in getattr(package, "extended_attributes", ())):
        return []
    from opspec.commands._files import spec_inputs

    worlds = [Path(path) for name, path in spec_inputs(spec_path, package)
              if path is not None and "opspec:WorldFile" in name and Path(path).is_file()]
    return [SideFile(path, "world file", checked=why is None, why_not=why or "")
            for path in worlds]
