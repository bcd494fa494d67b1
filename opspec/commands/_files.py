"""Checks every command makes on the files it is given: the input is a regular file (pipes and
devices are refused without blocking), and no output option names a file the same command
reads (``opspec run --trace SPEC`` would replace the spec with its own trace):
:func:`refuse_overwrite`, the one check every command that writes a file makes."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from opspec.errors import ConfigurationError

__all__ = ["Named", "check_nesting", "input_problem", "overwrite_problem", "refuse_overwrite",
           "same_file", "spec_inputs", "translation_problem", "unwritable", "write_problem"]

#: a file as the command line names it: (the option or argument, e.g. ``"--trace"``, path)
Named = tuple[str, "str | os.PathLike[str] | None"]


def input_problem(path: Path) -> str | None:
    """Why ``path`` cannot be read as the command's input (``"it does not exist"``, ``"it is
    a named pipe (FIFO), not a regular file"``…), or ``None``."""
    from opspec.files import not_a_file

    return not_a_file(path)


def _said(command: str, message: str) -> str:
    """``message`` as ``opspec COMMAND`` prints it itself (what reaches :func:`opspec.cli.main`
    as an error is prefixed there, and carries no prefix)."""
    return f"opspec {command}: {message}"


def translation_problem(command: str, source: Path, target: Path | None, *,
                        example: str) -> str | None:
    """Why ``opspec COMMAND IN -o OUT`` (a translation: ``compile``, ``preprocess``) cannot
    run: IN (``source``) cannot be read, or OUT (``target``; None: standard output) would
    replace IN or IN's companion user model, as the line the command prints (``opspec
    COMMAND: ...``). None when it can."""
    problem = input_problem(source)
    if problem is not None:
        from opspec.runs import where_to_look

        where = where_to_look(source)
        return _said(command, f"cannot read {source}: {problem}"
                     + (f" ({where})" if where else ""))
    from opspec.commands._spec import companion_user_model

    return overwrite_problem(command, [("-o", target)],
                             [("IN", source), ("IN's companion user model",
                                               companion_user_model(source))],
                             example=example)


def write_problem(target: Path, error: OSError) -> str:
    """``cannot write TARGET: why`` for ``error``, raised writing ``target``: when the folder
    it goes in is missing (or a file stands where a folder should), that folder, named; the
    operating system's bare "No such file or directory" names neither, and the "File exists"
    of making a folder where a file stands names nothing at all."""
    import errno

    folder = target.parent
    if error.errno in (errno.ENOENT, errno.ENOTDIR, errno.EEXIST):
        existing = next((path for path in (folder, *folder.parents) if path.exists()), None)
        if existing is not None and not existing.is_dir():
            return (f"cannot write {target}: {existing} is a file, not a folder (give a path "
                    "in a folder)")
        if existing != folder:
            return (f"cannot write {target}: the folder {folder} does not exist (create it "
                    "first)")
    return f"cannot write {target}: {error.strerror or error}"


def unwritable(target: Path, *, folder: bool = False) -> str | None:
    """Why ``target`` (a file, or with ``folder`` a folder, that a command writes once its
    work is done) cannot be written, found before that work starts (``opspec fit -o`` fitted
    and bootstrapped, ``model-check --report`` checked, for minutes, and only then said they
    could not write); None when it can. A temporary file is made and removed in the nearest
    folder that exists; nothing else is created."""
    import tempfile

    place = target if folder else target.parent
    existing = next((path for path in (place, *place.parents) if path.exists()), None)
    if existing is None or not existing.is_dir():
        return (f"cannot write {target}: {existing} is a file, not a folder (give a path "
                "in a folder)") if existing is not None else f"cannot write {target}"
    try:
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as error:
        return f"cannot write {target}: {existing}: {error.strerror or error}"
    return None


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


def _inside(path: Path, folder: Path) -> bool:
    try:
        return path.resolve().is_relative_to(folder.resolve())
    except (OSError, RuntimeError):
        return False


def overwrite_problem(command: str, writes: Iterable[Named], reads: Iterable[Named], *,
                      folders: Iterable[Named] = (), example: str = "") -> str | None:
    """The line ``opspec COMMAND`` prints when a file the command writes (``writes``), or a
    file inside a folder it fills (``folders``: every file there may be replaced), is one the
    command reads (``reads``), naming both; ``None`` when none is. ``example``: a file name
    to suggest."""
    problem = _overwrite(writes, reads, folders=folders, example=example)
    return None if problem is None else _said(command, problem)


def _overwrite(writes: Iterable[Named], reads: Iterable[Named], *, folders: Iterable[Named],
               example: str) -> str | None:
    """:func:`overwrite_problem`'s message, without the command's prefix."""
    instead = f", e.g. {example}" if example else ""
    inputs = [(what, Path(path)) for what, path in reads if path]
    for what, path in writes:
        if not path:
            continue
        target = Path(path)
        for read_as, source in inputs:
            if same_file(source, target):
                shown = (f"{target}" if str(target) == str(source)
                         else f"{target} (the same file as {source})")
                return (f"{what} {shown} is the file this command reads as {read_as}; "
                        f"refusing to overwrite it (give {what} another file{instead})")
    for what, path in folders:
        if not path:
            continue
        for read_as, source in inputs:
            if _inside(source, Path(path)):
                return (f"{what} writes into {path}, which holds {source}, a file this "
                        f"command reads as {read_as}; refusing to overwrite it (move "
                        f"{read_as} out of it, or choose another folder)")
    return None


def refuse_overwrite(writes: Iterable[Named], reads: Iterable[Named], *,
                     folders: Iterable[Named] = (), example: str = "") -> None:
    """Raise a :class:`ConfigurationError` (exit status 2, nothing written) when an output
    would replace an input (:func:`overwrite_problem`). Its message carries no prefix:
    :func:`opspec.cli.main` begins it with the command that was run."""
    problem = _overwrite(writes, reads, folders=folders, example=example)
    if problem is not None:
        raise ConfigurationError(problem)


def spec_inputs(spec: str | os.PathLike[str], package: Any) -> list[Named]:
    """The files a run of the spec at ``spec`` reads besides the spec: its world file
    (``opspec:WorldFile``) and the specs its modes load (``opspec:Mode Source``), relative to
    the spec's folder."""
    base = Path(spec).parent
    found: list[Named] = []
    for attribute in getattr(package, "extended_attributes", ()):
        if attribute.name == "opspec:WorldFile" and attribute.value:
            found.append(("its opspec:WorldFile", base / attribute.value))
    for mode in getattr(package, "modes", ()):
        if mode.source:
            found.append((f"the Source of its mode {mode.id!r}", base / mode.source))
    return found


def check_nesting(path: str | os.PathLike[str], what: str) -> None:
    """A :class:`ConfigurationError` at ``path`` when the TOML file nests deeper than opspec
    reads (:data:`opspec.files.MAX_NESTING`), for readers that parse with ``tomllib`` itself
    (the engine configuration): Python's parser recurses once per level, and 100,000 ``[``
    would end in an internal error. Anything else wrong is left for the reader to say."""
    import tomllib

    from opspec.errors import SourceLocation
    from opspec.files import MAX_NESTING, read_text, toml_loads

    try:
        toml_loads(read_text(path))
    except tomllib.TOMLDecodeError as error:
        if "nest too deeply" in str(error):
            raise ConfigurationError(f"{what} is not valid TOML: {error}",
                                     location=SourceLocation(str(path)),
                                     hint="check the brackets: opspec reads at most "
                                     f"{MAX_NESTING} levels") from None
    except (OSError, UnicodeDecodeError):
        pass
