"""Whom a fitted model was fitted on: the ``[fitted_on]`` table ``opspec fit`` writes, and
``opspec model-check`` reads to say when the people it checks the model against include
people the model was fitted on (a check on them is no check on new people).

::

    [fitted_on]
    persons = ["P01", "P02", "P03"]

Like ``[uncertainty]`` it is not part of the model: the loader checks it when it loads the
file, and :func:`fitted_persons` reads it from the file a reference names.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from opspec.errors import UserModelError
from opspec.toml_lines import located

__all__ = ["TABLE", "check_table", "fitted_on_text", "fitted_persons"]

TABLE = "fitted_on"


def fitted_on_text(persons: Iterable[str]) -> str:
    """The ``[fitted_on]`` table as TOML text."""
    import tomli_w

    return ("\n# ---- whom the model was fitted on: `opspec model-check` says when the people "
            "it checks are among them\n" + tomli_w.dumps({TABLE: {"persons": list(persons)}}))


def check_table(table: Any, path: str) -> tuple[str, ...]:
    """The persons of a ``[fitted_on]`` table, or a UserModelError naming the key."""
    if not isinstance(table, dict) or set(table) - {"persons"}:
        raise UserModelError("must be a table with one key, persons",
                             location=located(path, TABLE),
                             hint="write it again with `opspec fit`")
    persons = table.get("persons", [])
    if not isinstance(persons, list) or not all(isinstance(p, str) for p in persons):
        raise UserModelError("must be a list of the persons' identifiers",
                             location=located(path, f"{TABLE}.persons"),
                             hint="write it again with `opspec fit`")
    return tuple(persons)


def fitted_persons(ref: str | None) -> tuple[str, ...] | None:
    """The persons the model file ``ref`` was fitted on; None when ``ref`` is no file (a
    preset, a composition) or the file does not say."""
    if ref is None or "," in ref or not Path(ref).is_file():
        return None
    from opspec.usermodels.loader import _read

    table = _read(Path(ref)).get(TABLE)
    return None if table is None else check_table(table, ref)
