"""A translation's output (``opspec compile``, ``opspec preprocess``) gets the spec's companion
files it would otherwise miss: a run of ``OUT`` looks for ``OUT.users.toml`` beside it, not for
``IN.users.toml``, and ``preprocess`` copies a world file that would lie outside ``OUT``'s
folder tree. An existing different file is kept, and said."""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["copy_companion", "copy_user_model"]


def copy_user_model(command: str, source: Path, target: Path) -> None:
    """Copy the spec's companion ``SPEC.users.toml`` to the output's companion name, so
    ``opspec run OUT`` and ``opspec evaluate OUT`` draw the same users."""

    from opspec.request import companion_user_model

    model = companion_user_model(source)
    if model is None:
        return
    copy = target.with_name(target.name.removesuffix(target.suffix) + ".users.toml")
    copy_companion(command, model, copy, "user model")


def copy_companion(command: str, original: Path, copy: Path, what: str) -> None:
    """Copy ``original`` to ``copy`` for the output (an existing different file is kept)."""
    import shutil

    from opspec.commands._files import same_file

    if same_file(original, copy):
        return
    try:
        if copy.exists():
            if copy.read_bytes() != original.read_bytes():
                print(f"opspec {command}: kept {copy}, which differs from {original} (the "
                      f"output's {what})", file=sys.stderr)
            return
        shutil.copyfile(original, copy)
    except OSError as error:
        print(f"opspec {command}: could not copy the {what} {original} to {copy}: "
              f"{error.strerror or error}", file=sys.stderr)
        return
    print(f"{copy}: {what} of the output, copied from {original}")
