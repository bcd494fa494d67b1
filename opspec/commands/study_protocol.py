"""The keys a study protocol may hold, checked before ``opspec study`` runs anything.

:func:`opspec.tui.study.load_protocol` checks the ``[study]`` table's keys; a misspelt key of a
``[[variants]]`` table, or a table of its own beside the two (``[varaints]``), was read as
absent without a word: ``tld = "..."`` left the variant with no briefing, and its
participants started the session without being told anything. Refused here, at
``file:line: key``, with the keys that are meant.
"""

from __future__ import annotations

import difflib
from pathlib import Path

from opspec.errors import ConfigurationError
from opspec.toml_lines import located

__all__ = ["refuse_unknown_keys"]

_TOP = ("study", "variants")
_VARIANT = ("id", "spec", "told")


def _unknown(where: str, key: str, known: tuple[str, ...], name: str,
             hint: str) -> ConfigurationError:
    close = difflib.get_close_matches(name, known, n=1)
    meant = f" (did you mean {close[0]!r}?)" if close else ""
    return ConfigurationError(f"unknown key {name!r}{meant}", location=located(where, key),
                              hint=hint)


def refuse_unknown_keys(path: str | Path) -> None:
    """A ConfigurationError naming ``file:line: key`` for the first key of the protocol
    ``path`` that no part of ``opspec study`` reads (call it before ``load_protocol``: a
    misspelt ``[[varaints]]`` would otherwise be said to be no variants at all)."""
    from opspec.toml_files import read_toml

    where = str(path)
    data = read_toml(Path(path), what="the protocol")
    for name in data:
        if name not in _TOP:
            raise _unknown(where, name, _TOP, name, "a protocol holds a [study] table "
                           "and [[variants]] tables, nothing else")
    for i, variant in enumerate(data.get("variants") or []):
        for name in variant if isinstance(variant, dict) else ():
            if name not in _VARIANT:
                raise _unknown(where, f"variants[{i}].{name}", _VARIANT, name,
                               f"keys of [[variants]]: {', '.join(_VARIANT)}")
