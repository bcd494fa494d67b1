"""Opening the files users name — user models, scripts and recordings, engine configurations,
traces, scenario files, device profiles, world files — without ever blocking.

A named pipe (FIFO), a device (``/dev/zero``), a socket or a folder given where a file is
expected is refused before it is opened; a regular file is opened non-blocking and checked
again, so a path swapped for a pipe in between cannot block either. Failures are
:class:`OSError` whose ``strerror`` is one phrase for a one-line message (``"it is a named
pipe (FIFO), not a regular file"``, ``"Permission denied"``): each loader wraps it in its own
error (exit status 2 at the command line, docs/validation.md).

This module sits at the bottom of the layers (pyproject.toml) so that every loader, the
engine's included, can use it; it imports nothing of opspec. (:mod:`opspec.xpdl.reader` reads
specs through these too, adding its size limit and XPDL-specific messages.)
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import stat
import tomllib
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any, BinaryIO

__all__ = ["EXTERNAL_PATH_VARIABLE", "MAX_NESTING", "NotARegularFile", "allowed_roots",
           "companion_outside", "file_name", "json_loads", "not_a_file", "open_regular",
           "outside_message", "outside_roots", "read_bytes", "read_text", "reason", "toml_load",
           "toml_loads"]

#: Folders, besides the root spec's own folder tree, whose files specs may refer to (separated
#: by ``os.pathsep``: ``OPSPEC_EXTERNAL_PATH=/opt/xpdl-lib:/srv/shared``; docs/validation.md).
#: It covers every file a spec names: ExternalPackage hrefs, mode sources, world files.
EXTERNAL_PATH_VARIABLE = "OPSPEC_EXTERNAL_PATH"


class NotARegularFile(OSError):
    """A path that is not a regular file (its ``strerror`` says what it is)."""

    def __init__(self, why: str) -> None:
        super().__init__(why)
        self.strerror = why


def not_a_file(path: str | os.PathLike[str]) -> str | None:
    """Why ``path`` cannot be read as a file without even opening it (``"it does not exist"``,
    ``"it is a folder"``, ``"it is a named pipe (FIFO), not a regular file"``…), or ``None``
    for a regular file (or a link to one). Never blocks: nothing is opened."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "it does not exist"
    except OSError as error:
        return f"it cannot be examined: {error.strerror or type(error).__name__}"
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "it is a folder"
    kind = ("a named pipe (FIFO)" if stat.S_ISFIFO(mode)
            else "a character device" if stat.S_ISCHR(mode)
            else "a block device" if stat.S_ISBLK(mode)
            else "a socket" if stat.S_ISSOCK(mode)
            else "a special file")
    return f"it is {kind}, not a regular file"


def open_regular(path: str | os.PathLike[str]) -> BinaryIO:
    """Open a regular file for reading in binary; an :class:`OSError` for anything else
    (:class:`NotARegularFile` for a pipe, device, socket or folder). Never blocks."""
    why = not_a_file(path)
    if why is not None:
        if why == "it does not exist":
            raise FileNotFoundError(2, "No such file or directory", os.fspath(path))
        raise NotARegularFile(why)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    descriptor = os.open(path, flags)
    try:
        if not stat.S_ISREG(os.fstat(descriptor).st_mode):
            raise NotARegularFile("it is not a regular file")
        return os.fdopen(descriptor, "rb")
    except BaseException:
        os.close(descriptor)
        raise


def read_bytes(path: str | os.PathLike[str]) -> bytes:
    """The bytes of the regular file ``path``; :class:`OSError` as :func:`open_regular`."""
    with open_regular(path) as stream:
        return stream.read()


def read_text(path: str | os.PathLike[str], encoding: str = "utf-8") -> str:
    """The text of the regular file ``path`` (:class:`UnicodeDecodeError` for bad bytes)."""
    return read_bytes(path).decode(encoding)


def reason(error: OSError) -> str:
    """The phrase of a one-line message for ``error``: ``"Permission denied"``, ``"it is a
    named pipe (FIFO), not a regular file"``…"""
    return error.strerror or type(error).__name__


# ---------------------------------------------------------------- files a spec names


def _key(path: Path) -> Path:
    try:
        return path.resolve()
    except (OSError, RuntimeError):
        return path.absolute()


def allowed_roots(root_path: str | os.PathLike[str] | None) -> tuple[Path, ...]:
    """The folders whose files a spec in ``root_path`` may refer to: its own folder (the
    working folder for a spec that has no file) and those listed in
    :data:`EXTERNAL_PATH_VARIABLE` (each with every folder below it)."""
    roots = [_key(Path(root_path)).parent if root_path else _key(Path.cwd())]
    for entry in os.environ.get(EXTERNAL_PATH_VARIABLE, "").split(os.pathsep):
        if entry.strip():
            roots.append(_key(Path(entry.strip()).expanduser()))
    return tuple(dict.fromkeys(roots))


def outside_roots(target: Path, roots: Sequence[Path]) -> str | None:
    """``None`` when ``target`` (links followed) lies inside one of ``roots``; otherwise a
    phrase for the message saying where it really is."""
    real = _key(target)
    if any(real.is_relative_to(root) for root in roots):
        return None
    shown = str(target) if real == target.absolute() else f"{target}, which is {real}"
    return shown


def companion_outside(spec: str | os.PathLike[str] | None, name: str, what: str
                      ) -> tuple[str, str] | None:
    """``(message, hint)`` when the file ``name`` that the spec in ``spec`` names (relative to
    the spec's folder: an ``opspec:Mode Source``, an ``opspec:WorldFile``) leads outside the
    spec's folder tree and :data:`EXTERNAL_PATH_VARIABLE`; ``None`` when it may be read.
    ``what`` names the reference in the message (``"opspec:WorldFile"``)."""
    base = Path(spec).parent if spec else Path.cwd()
    roots = allowed_roots(spec)
    where = outside_roots(base / name, roots)
    if where is None:
        return None
    return outside_message(f"{what} {name!r}", where, roots)


def outside_message(reference: str, where: str, roots: Sequence[Path], *,
                    files: str = "the files a spec names", thing: str = "the file"
                    ) -> tuple[str, str]:
    """``(message, hint)`` refusing ``reference`` (``"opspec:WorldFile 'w.toml'"``), which
    leads outside the spec's folder to ``where`` (from :func:`outside_roots`): opspec reads
    ``files`` only inside ``roots``; the hint says to copy ``thing`` in or allow its folder."""
    folders = " or ".join(str(r) for r in roots)
    message = (f"{reference} leads outside the spec's folder ({where}); opspec reads {files} "
               f"only inside {folders}")
    hint = (f"copy {thing} into the spec's folder, or allow its folder with the environment "
            f"variable {EXTERNAL_PATH_VARIABLE} (docs/validation.md)")
    return message, hint


# ---------------------------------------------------------------- names from a spec


_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")


def file_name(name: str, most: int = 80) -> str:
    """``name`` (from a spec: a metric's Name) as one safe component of a file name: letters,
    digits, ``_``, ``-`` and inner dots only, so ``../../x`` or ``a/b`` cannot lead out of the
    folder it is written in. A simple name stays as it is; any other gets a short digest of
    the original, so two names that differ only in what was replaced stay two files."""
    safe = _UNSAFE.sub("_", name).strip("._-")[:most]
    if safe and safe == name:
        return safe
    digest = hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    return f"{safe or 'name'}-{digest}"


# ---------------------------------------------------------------- TOML and JSON, bounded

#: How deeply arrays and tables (objects) may nest in a TOML or JSON file opspec reads. No
#: file of opspec nests more than a handful of levels; Python's parsers recurse once per
#: level, and a file of 100,000 ``[`` would end in a RecursionError (an internal error).
MAX_NESTING = 64

#: Digits an integer of a JSON file may have (Python refuses to convert more than 4,300,
#: with a ValueError that is not a JSONDecodeError).
MAX_DIGITS = 4300


def _too_deep(document: object, most: int = MAX_NESTING) -> bool:
    """Whether ``document`` (parsed) nests deeper than ``most`` levels (no recursion)."""
    stack: list[tuple[object, int]] = [(document, 0)]
    while stack:
        value, depth = stack.pop()
        if isinstance(value, dict):
            children: Iterable[object] = value.values()
        elif isinstance(value, list):
            children = value
        else:
            continue
        if depth >= most:
            return True
        stack.extend((child, depth + 1) for child in children)
    return False


_NESTED = (f"arrays and tables nest too deeply (opspec reads at most {MAX_NESTING} levels)")


def toml_loads(text: str) -> dict[str, Any]:
    """``tomllib.loads(text)``, with nesting beyond :data:`MAX_NESTING` a
    ``tomllib.TOMLDecodeError`` like any other syntax error (the callers' messages name
    the file), never a RecursionError."""
    try:
        document = tomllib.loads(text)
    except RecursionError:
        raise tomllib.TOMLDecodeError(_NESTED) from None
    if _too_deep(document):
        raise tomllib.TOMLDecodeError(_NESTED)
    return document


def toml_load(stream: BinaryIO) -> dict[str, Any]:
    """:func:`toml_loads` of a binary stream, as ``tomllib.load`` reads one (UTF-8)."""
    data = stream.read()
    try:
        text = data.decode()
    except AttributeError:
        raise TypeError("toml_load needs a binary stream") from None
    return toml_loads(text)


def json_problem(error: Any, *, one_line: bool = False) -> str:
    """A ``json.JSONDecodeError``'s message as a whole sentence with its column (json ends
    some with "at" and leaves the place to its own str(): "Invalid control character at:
    line 1 column 30"); the line is the caller's to name. ``one_line``: the document is one
    line of a file (a JSON Lines trace), so a place past its newline is the line ending too
    soon."""
    if "(" in error.msg:        # opspec's own (nested too deeply, a number too large): no place
        return str(error.msg)
    place = ("the end of the line" if one_line and error.lineno > 1
             else f"column {error.colno}")
    return f"{error.msg} {place}" if error.msg.endswith(" at") else f"{error.msg} at {place}"


def json_loads(text: str | bytes, *, most: int = MAX_NESTING) -> Any:
    """``json.loads(text)``, with nesting beyond ``most`` levels or an integer of more
    than :data:`MAX_DIGITS` digits a ``json.JSONDecodeError`` like any other syntax error,
    never a RecursionError or a bare ValueError."""
    nested = f"arrays and objects nest too deeply (opspec reads at most {most} levels)"
    doc = text if isinstance(text, str) else text.decode("utf-8", "surrogateescape")
    try:
        value = json.loads(text)
    except RecursionError:
        raise json.JSONDecodeError(nested, doc, 0) from None
    except json.JSONDecodeError:
        raise
    except ValueError as error:         # an integer past Python's conversion limit
        raise json.JSONDecodeError(f"a number is too large to read ({error})", doc,
                                   0) from None
    if _too_deep(value, most):
        raise json.JSONDecodeError(nested, doc, 0)
    return value
