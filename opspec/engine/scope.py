"""What an instance's expressions read: its own fields, then the package's.

:class:`Scope` is a :class:`collections.ChainMap` of the two dictionaries whose lookup asks
each map whether it has the key instead of trying it and catching its ``KeyError``: a
package-level field (``bump``, ``escaping``, ``level`` of the robot specs) read by an instance
without a field of that name raised and caught an exception per read, about four times the
cost of the lookup, on every workflow instance of a periodic spec. The maps are plain
dictionaries, where ``key in m`` and ``m[key]`` agree, so the value found is the same.

Left out of the compiled modules (``opspec._native``): a compiled class cannot extend a
Python one such as ChainMap.
"""

from __future__ import annotations

from collections import ChainMap
from typing import Any

__all__ = ["Scope"]


class Scope(ChainMap[str, Any]):
    """A ChainMap over dictionaries, looked up without an exception per map."""

    def __getitem__(self, key: str) -> Any:
        for mapping in self.maps:
            if key in mapping:
                return mapping[key]
        return self.__missing__(key)
