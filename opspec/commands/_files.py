"""Checks the commands that read one spec and write another file share: the input is a regular
file (pipes and devices are refused without blocking) and the output is not the input."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["input_problem", "same_file"]


def input_problem(path: Path) -> str | None:
    """Why ``path`` cannot be read as the command's input (``"it does not exist"``, ``"it is
    a named pipe (FIFO), not a regular file"``…), or ``None``."""
    from opspec.files import not_a_file

    return not_a_file(path)


def same_file(source: Path, target: Path) -> bool:
    """True when writing ``target`` would replace ``source``: the same path, a link to it, or
    another hard link of the same file."""
    try:
        return os.path.samefile(source, target)
    except OSError:          # the output does not exist yet: compare where the paths lead
        try:
            return source.resolve() == target.resolve()
        except (OSError, RuntimeError):
            return False
