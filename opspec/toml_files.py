"""Reading the TOML files people write: one reader, one set of located errors.

User models (``SPEC.users.toml``, populations), scripts and recordings, scenario files,
device profiles and world files are all read by :func:`read_toml`: a pipe or a device is
refused without blocking (:mod:`opspec.files`), and whatever goes wrong is one line naming
the file — ``cannot read the user model: Permission denied``, ``not UTF-8 text: byte 0xe9
at offset 12``, ``FILE:3: not valid TOML: Expected '=' after a key in a key/value pair (at
line 3, column 7)`` (at tomllib's line) — raised as the caller's own error class (a user
model's :class:`~opspec.errors.UserModelError`, a profile's
:class:`~opspec.errors.BindingError`).
"""

from __future__ import annotations

import os
import tomllib
from typing import Any

from opspec.errors import ConfigurationError, OpspecError, SourceLocation

__all__ = ["TOML_HINT", "parse_toml", "read_toml"]

TOML_HINT = "check quotes, brackets and '=' signs near that line (TOML: https://toml.io)"


def parse_toml(text: str, *, where: str, error: type[OpspecError] = ConfigurationError,
               location: SourceLocation | None = None, hint: str | None = None,
               what: str | None = None) -> dict[str, Any]:
    """The document in ``text`` (read from ``where``); a syntax error is ``error`` at
    ``where`` and the line tomllib names (at ``location``, the place that named the file,
    when tomllib names no line or ``location`` is this file without a line), with tomllib's
    message, which names the line and column (``what`` in front: ``the script is not valid
    TOML: …``)."""
    from opspec.files import toml_loads

    try:
        return toml_loads(text)           # nesting bounded: a syntax error, never recursion
    except tomllib.TOMLDecodeError as problem:
        from opspec.toml_lines import syntax_line

        said = f"{what} is not valid TOML" if what else "not valid TOML"
        line = syntax_line(str(problem))
        if line is not None and (location is None or (location.line is not None
                                                       and location.path != where)):
            # the mistake is in this file, at tomllib's line: placed there (not at the line
            # of the spec that names the file), so that an editor jumps to it
            location = SourceLocation(where, line)
        raise error(_named(f"{said}: {problem}", where, location),
                    location=location or SourceLocation(where),
                    hint=hint or TOML_HINT) from None


def read_toml(path: str | os.PathLike[str], *, what: str,
              error: type[OpspecError] = ConfigurationError,
              location: SourceLocation | None = None, hint: str = "",
              syntax_hint: str | None = None,
              missing: tuple[str, str] | None = None) -> dict[str, Any]:
    """The TOML document in the file ``path`` (``what`` it is, for the messages: ``"user
    model"``, ``"device profile devices/x.toml"``). Errors are ``error`` at ``location``
    (default: the file itself; give the place that named the file, such as a spec's line,
    and the message names the file). ``hint`` goes with a file that cannot be read,
    ``syntax_hint`` with a TOML syntax error; ``missing`` is the message and hint for a file
    that does not exist."""
    from opspec.files import read_bytes, reason

    where = os.fspath(path)
    at = location or SourceLocation(where)

    def refuse(message: str, advice: str) -> OpspecError:
        message = _named(message, where, location)
        # a message that names the file needs no location in front of it saying it again
        return error(message, location=None if location is None and where in message
                     else at, hint=advice)

    try:
        raw = read_bytes(path)            # a pipe or device is refused, never read (blocks)
    except FileNotFoundError:
        if missing is not None:
            raise error(missing[0], location=location, hint=missing[1]) from None
        raise refuse(f"cannot read {what}: it does not exist", hint) from None
    except OSError as problem:
        raise refuse(f"cannot read {what}: {reason(problem)}", hint) from None
    try:
        # TOML files are UTF-8; the byte-order mark Windows editors put in front is no
        # mistake of the text (tomllib called it an "Invalid statement" at line 1)
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as problem:
        raise refuse(f"not UTF-8 text: byte 0x{problem.object[problem.start]:02x} at offset "
                     f"{problem.start}", "save the file as UTF-8") from None
    return parse_toml(text, where=where, error=error, location=location, hint=syntax_hint)


def _named(message: str, where: str, location: SourceLocation | None) -> str:
    """The message, naming the file when the error is located at a line of another file
    (the spec's line that names a world file)."""
    if location is None or location.line is None or location.path == where or where in message:
        return message
    return f"{where}: {message}"
