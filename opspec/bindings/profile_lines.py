"""A device profile's error placed at the line its dotted key (``serial.baudrate``,
``operations.dispense.command``) is written on, so that it reads ``file:line: key`` (a TOML
syntax error ``file:line:``) and an editor can jump to it; the scanning is
:mod:`opspec.toml_lines`'s."""

from __future__ import annotations

from opspec.errors import BindingError, SourceLocation
from opspec.toml_lines import key_line, syntax_line
from opspec.toml_lines import located as key_location

__all__ = ["key_line", "located"]


def located(error: BindingError, where: str) -> BindingError:
    """``error`` about the profile file ``where``, placed at its line: the line its key is
    written on (or the nearest written parent's), or a syntax error's line. Unchanged when
    it has a line already, is about another file, or names no line to find."""
    at = error.location
    if at is None or at.line is not None or at.path != where:
        return error
    line = syntax_line(error.message)
    if line is None and at.key:
        # read as the profile was (past a byte-order mark an editor may have saved)
        line = key_location(where, at.key).line
    if line is None:
        return error
    return BindingError(error.message, location=SourceLocation(at.path, line, at.key),
                        hint=error.hint)
