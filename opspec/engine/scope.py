"""What an instance's expressions read: its own fields, then the package's.

:class:`Scope` is the mapping a workflow instance's conditions, expressions and activities
read: a field of the instance hides a package-level field of the same name, a package-level
field the instance does not declare (``bump``, ``escaping``, ``level`` of the robot specs) is
read from the package. It keeps the meaning of ``collections.ChainMap(fields, package)``:
lookups, ``in``, ``len``, iteration order (the package's fields first, then the instance's
own new ones) and writes, which go to the instance's fields (the engine's assignments write
to the dictionaries themselves, not through the scope: see ``Flow.set_field``).

It is a class of its own instead of a ChainMap subclass so that mypyc compiles it
(``opspec._native``; a compiled class cannot extend ChainMap, a Python class): a periodic
spec makes a scope per workflow instance and reads it a few times in each, and the
interpreted ``ChainMap.__init__`` and ``__getitem__`` were about 4k instructions of the
instance's 37.5k (docs/engine-performance.md, "periodic path, fifth pass"). The
instance's fields are asked whether they have the key instead of tried and their
``KeyError`` caught (a package field read by an instance without that field raised and
caught an exception per read); the package's are tried last, their ``KeyError`` being the
scope's own.
"""

from __future__ import annotations

from collections.abc import Iterator, MutableMapping
from typing import Any, Final

__all__ = ["Scope"]

#: a field the instance does not have (``dict.get``'s default in :meth:`Scope.__getitem__`)
_MISSING: Final = object()


class Scope(MutableMapping[str, Any]):
    """An instance's fields over the package's fields, as ``ChainMap(fields, package)``."""

    def __init__(self, fields: dict[str, Any], package: dict[str, Any]) -> None:
        self.fields = fields
        self.package = package

    @property
    def maps(self) -> list[dict[str, Any]]:
        """The two dictionaries, first looked up first (ChainMap's attribute)."""
        return [self.fields, self.package]

    def __getitem__(self, key: str) -> Any:
        fields = self.fields
        if fields:                      # (empty, not looked in: most periodic workflows')
            value = fields.get(key, _MISSING)       # (one look-up, not ``in`` then ``[]``)
            if value is not _MISSING:
                return value
        return self.package[key]        # a field of neither: KeyError(key), as ChainMap's

    def get(self, key: str, default: Any = None) -> Any:
        fields = self.fields
        if fields:
            value = fields.get(key, _MISSING)
            if value is not _MISSING:
                return value
        return self.package.get(key, default)

    def __contains__(self, key: object) -> bool:
        return key in self.fields or key in self.package

    def __setitem__(self, key: str, value: Any) -> None:
        self.fields[key] = value

    def __delitem__(self, key: str) -> None:
        if key not in self.fields:
            raise KeyError(f"Key not found in the first mapping: {key!r}")
        del self.fields[key]

    def __iter__(self) -> Iterator[str]:
        keys = dict.fromkeys(self.package)
        keys.update(dict.fromkeys(self.fields))
        return iter(keys)

    def __len__(self) -> int:
        return len(self.fields.keys() | self.package.keys())

    def __bool__(self) -> bool:
        return bool(self.fields) or bool(self.package)

    def __copy__(self) -> Scope:
        """A copy with its own instance fields over the same package (ChainMap's ``copy``)."""
        return Scope(self.fields.copy(), self.package)

    def __reduce__(self) -> tuple[type[Scope], tuple[dict[str, Any], dict[str, Any]]]:
        # pickle and deepcopy rebuild it from its two maps (compiled, the default
        # reduction would call __init__ without them)
        return Scope, (self.fields, self.package)

    def __repr__(self) -> str:
        return f"Scope({self.fields!r}, {self.package!r})"
