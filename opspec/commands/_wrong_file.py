"""A file given to the wrong option of ``opspec run``: say which option it was given to and
which one it is meant for.

A user model passed to ``--script`` fails as a script with unknown keys, a spec passed to
``--user-model`` as TOML that cannot be read: the messages are right about the file but do
not say that the file is simply in the wrong place (a user model or script given as SPEC is
named so by the spec reader, :mod:`opspec.xpdl.not_a_spec`, at every door; here ``run``
adds which of its options it goes to). :func:`misplaced` looks at a file whose
reading failed and, when it is plainly a spec (XML, or a compiled ``.wfs``), a user model
(``format = "opspec-user-model"``) or a script (``steps``), says where it goes instead.
Only the error path reads the file again.

``opspec fit`` and ``model-check`` ask the same of their TRACE files and of model-check's
MODEL before reading them (:func:`refuse_misplaced_traces`, :func:`refuse_misplaced_model`).
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any

from opspec.errors import ConfigurationError, OpspecError, SpecError, UserModelError

__all__ = ["misplaced", "refuse_misplaced_model", "refuse_misplaced_traces"]

_SPEC = "the spec (the first argument: opspec run SPEC)"


def _same(a: str | Path, b: str | Path) -> bool:
    try:
        return Path(a).resolve() == Path(b).resolve()
    except (OSError, RuntimeError, ValueError):
        return False


def _what(path: str | Path) -> tuple[str, str] | None:
    """(what the file is, where it goes) when that is plain from its content."""
    from opspec.files import json_loads, read_bytes, toml_loads

    try:
        raw = read_bytes(path)
    except (OSError, OpspecError):
        return None
    head = raw.lstrip(b"\xef\xbb\xbf \t\r\n")
    if head.startswith(b"<"):
        kind = "BPMN" if b"omg.org/spec/BPMN" in head[:4096] else "XPDL"
        return f"a spec ({kind})", _SPEC
    document: Any = None
    with contextlib.suppress(ValueError, RecursionError):   # not JSON, not TOML: unknown
        document = (json_loads(raw) if head.startswith(b"{")
                    else toml_loads(raw.decode("utf-8")))
    if not isinstance(document, dict):
        return None
    if document.get("format") == "opspec-wfs":
        return "a compiled spec (.wfs)", _SPEC
    if document.get("format") == "opspec-user-model":
        return "a user model", "--user-model"
    if "steps" in document:
        return "a script", "--script"
    return None


def misplaced(error: OpspecError, given: tuple[tuple[str, str | None], ...]) -> OpspecError:
    """``error`` with a hint naming the option its file was given to and the one it is meant
    for (``given``: option and value), when the file is plainly of another kind; else
    ``error`` itself."""
    as_spec = isinstance(error, SpecError)      # a user model or script given as SPEC
    if (type(error) not in (ConfigurationError, UserModelError) and not as_spec
            or error.location is None):
        return error
    for option, value in given:
        # a spec error comes from reading SPEC, the others from the options' files
        if value is None or (option == "SPEC") != as_spec or not _same(
                error.location.path, value):
            continue
        found = _what(value)
        if found is None or found[1] == (_SPEC if option == "SPEC" else option):
            return error
        what, goes = found
        hint = (f"given to {option}, but this is {what}: give it as {goes}" if goes == _SPEC
                else f"given {'as' if option == 'SPEC' else 'to'} {option}, but this is "
                f"{what}: give it to {goes}")
        if as_spec:     # the reader's complaint about the XML is beside the point
            return SpecError(error.message, location=error.location, hint=hint)
        return type(error)(error.message, location=error.location, hint=hint)
    return error


def refuse_misplaced_traces(values: tuple[str, ...] | list[str], command: str) -> None:
    """Refuse, before anything is read as a trace, a TRACE of ``opspec fit`` or
    ``model-check`` (``command``) that is plainly a spec or a user model: read as JSON Lines
    it failed with "not valid JSON" at its line 1, which says nothing of the mix-up."""
    for value in values:
        if not Path(value).is_file():
            continue
        found = _what(value)
        if found is None or found[1] == "--script":     # a recording is a trace to fit
            continue
        what = found[0]
        if found[1] == "--user-model":
            hint = ("one user model, the first argument: opspec model-check MODEL TRACE..."
                    if command == "model-check" else
                    "opspec fit writes the model it fits to -o MODEL.toml; give it traces")
        else:
            hint = ("record traces with opspec run SPEC --trace FILE, opspec evaluate SPEC "
                    "--export jsonl or opspec walkthrough SPEC"
                    + ("; the spec's outcome metrics are checked with --spec SPEC"
                       if command == "model-check" else ""))
        raise UserModelError(f"{value}: {what}, not a trace (TRACE: the .jsonl traces, or "
                             "folders of them)", hint=hint)


def refuse_misplaced_model(ref: str) -> None:
    """Refuse a MODEL of ``opspec model-check`` that is plainly traces (a folder, a .jsonl
    file: the arguments swapped) or a spec, which the TOML reader called "not valid TOML"
    or "no preset called …"."""
    path = Path(ref)
    swapped = "the user model goes first: opspec model-check MODEL TRACE..."
    if path.is_dir():
        raise UserModelError(f"{ref}: a folder, not a user model (MODEL: a user-model TOML "
                             "file or a preset)", hint=swapped)
    if not path.is_file():
        return
    found = _what(ref)
    if path.suffix.lower() == ".jsonl" and found is None:
        raise UserModelError(f"{ref}: a trace, not a user model (MODEL: a user-model TOML "
                             "file or a preset)", hint=swapped)
    if found is not None and found[1] == _SPEC:
        raise UserModelError(f"{ref}: {found[0]}, not a user model (MODEL: a user-model "
                             "TOML file or a preset)",
                             hint="give the spec with --spec SPEC to check its outcome "
                             "metrics too")
